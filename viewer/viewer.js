// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The viewer of the page that `proxima view` and proxima.view() write
// (viewer/viewer.cpp fills page.html with three.js, this file and the data).
// three.js is inline as the text of <script id="three-source">, an ES
// module: it is imported from a Blob URL, so the page needs no server, no
// network and no build step. Everything is drawn from the data in
// <script id="proxima-data"> (world-frame coordinates): the bodies, the
// closest points and the segment between them, the witness features, the
// normal, the label with the distance (or depth) and its certificate, or a
// scene step's close pairs coloured by distance.
//
// When the page has drawn its first frame, <body data-rendered="yes"> is
// set; any error is shown in #errors, sent to console.error and leaves
// data-rendered="error" (the browser test reads both).
(function () {
  'use strict';

  const COLOR_A = 0x3b7dd8;
  const COLOR_B = 0xe08a1e;
  const COLOR_WITNESS = 0xd81b60;
  const COLOR_SEGMENT = 0x111111;
  const COLOR_NORMAL = 0x2a9d4b;

  function report(error) {
    const text = error && error.stack ? error.stack : String(error);
    document.getElementById('errors').textContent += text + '\n';
    document.body.dataset.rendered = 'error';
    console.error('proxima view: ' + text);
  }
  window.addEventListener('error', (event) => report(event.error || event.message));

  // Shortest text that reads back as the same double (as `proxima query`'s
  // numbers do): the label can be compared with the answer exactly.
  function num(x) {
    if (x === null || x === undefined) return 'n/a';
    if (x === Infinity || x === -Infinity) return x > 0 ? '+inf' : '-inf';
    return String(x);
  }

  // A small orbit control: the camera looks at `target` from spherical
  // coordinates (radius, theta about +z, phi from +z). Drag turns, shift
  // drag or right drag pans in the view plane, the wheel zooms.
  function OrbitControl(THREE, camera, element, onChange) {
    const target = new THREE.Vector3();
    let radius = 1, theta = Math.PI / 4, phi = Math.PI / 3;
    let drag = null;
    const update = () => {
      phi = Math.min(Math.max(phi, 1e-3), Math.PI - 1e-3);
      const s = Math.sin(phi);
      camera.position.set(target.x + radius * s * Math.cos(theta),
                          target.y + radius * s * Math.sin(theta),
                          target.z + radius * Math.cos(phi));
      camera.up.set(0, 0, 1);
      camera.lookAt(target);
      camera.near = radius / 1000;
      camera.far = radius * 1000;
      camera.updateProjectionMatrix();
      onChange();
    };
    element.addEventListener('contextmenu', (e) => e.preventDefault());
    element.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      element.setPointerCapture(e.pointerId);
    });
    element.addEventListener('pointerup', (e) => {
      drag = null;
      element.releasePointerCapture(e.pointerId);
    });
    element.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX;
      drag.y = e.clientY;
      if (drag.pan) {
        // One pixel moves the target by the visible height / canvas height.
        const perPixel = 2 * radius * Math.tan((camera.fov * Math.PI) / 360) / element.clientHeight;
        const right = new THREE.Vector3().setFromMatrixColumn(camera.matrix, 0);
        const up = new THREE.Vector3().setFromMatrixColumn(camera.matrix, 1);
        target.addScaledVector(right, -dx * perPixel).addScaledVector(up, dy * perPixel);
      } else {
        theta -= dx * 0.01;
        phi -= dy * 0.01;
      }
      update();
    });
    element.addEventListener('wheel', (e) => {
      e.preventDefault();
      radius *= Math.exp(e.deltaY * 0.001);
      update();
    }, { passive: false });
    return {
      // Looks at `center` from far enough to see a ball of radius `size`;
      // with `across` (the pair's normal), from a side square to it, so that
      // the segment and the normal are not foreshortened.
      frame(center, size, across) {
        target.copy(center);
        if (across) theta = Math.atan2(across[1], across[0]) + Math.PI / 2;
        radius = 1.35 * size / Math.tan((camera.fov * Math.PI) / 360);
        update();
      },
    };
  }

  // One convex piece: translucent faces, its edges, and its vertices when it
  // has no faces (a point or a segment).
  function pieceObjects(THREE, piece, color, wireframe, opacity) {
    const objects = [];
    const positions = new THREE.Float32BufferAttribute(piece.positions, 3);
    if (piece.triangles.length > 0) {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', positions);
      geometry.setIndex(piece.triangles);
      geometry.computeVertexNormals();
      const material = new THREE.MeshStandardMaterial({
        color, transparent: true, opacity, side: THREE.DoubleSide,
        flatShading: true, depthWrite: false, roughness: 0.7,
      });
      const mesh = new THREE.Mesh(geometry, material);
      mesh.userData.faces = true;
      objects.push(mesh);
    }
    const lines = new THREE.BufferGeometry();
    lines.setAttribute('position', positions);
    lines.setIndex(piece.edges);
    objects.push(new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ color, transparent: true, opacity: 0.5 })));
    if (piece.triangles.length === 0) {
      const points = new THREE.BufferGeometry();
      points.setAttribute('position', positions);
      objects.push(new THREE.Points(points, new THREE.PointsMaterial({ color, size: 6, sizeAttenuation: false })));
    }
    for (const o of objects) if (o.userData.faces) o.visible = !wireframe;
    return objects;
  }

  function ball(THREE, at, radius, color) {
    const mesh = new THREE.Mesh(new THREE.SphereGeometry(radius, 20, 14),
                                new THREE.MeshStandardMaterial({ color, roughness: 0.4 }));
    mesh.position.set(at[0], at[1], at[2]);
    return mesh;
  }

  // A tube between two points (lines are one pixel wide in WebGL).
  function rod(THREE, from, to, radius, color) {
    const a = new THREE.Vector3(...from), b = new THREE.Vector3(...to);
    const length = a.distanceTo(b);
    const group = new THREE.Group();
    if (length > 0) {
      const mesh = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, length, 12),
                                  new THREE.MeshBasicMaterial({ color }));
      mesh.position.copy(a).add(b).multiplyScalar(0.5);
      mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
      group.add(mesh);
    }
    return group;
  }

  // A witness feature: its vertices as balls, its edge (or triangle's
  // edges) as rods, and a face's whole facet filled.
  function witnessObjects(THREE, feature, size) {
    const objects = [];
    const p = feature.points;
    for (const v of p) objects.push(ball(THREE, v, size * 0.012, COLOR_WITNESS));
    for (let i = 0; i < p.length && p.length > 1; ++i) {
      if (p.length === 2 && i === 1) break;
      objects.push(rod(THREE, p[i], p[(i + 1) % p.length], size * 0.005, COLOR_WITNESS));
    }
    if (feature.face.length >= 3) {
      const flat = [];
      for (let i = 1; i + 1 < feature.face.length; ++i) {
        flat.push(...feature.face[0], ...feature.face[i], ...feature.face[i + 1]);
      }
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(flat, 3));
      objects.push(new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({
        color: COLOR_WITNESS, transparent: true, opacity: 0.35, side: THREE.DoubleSide, depthWrite: false,
      })));
    }
    return objects;
  }

  // Distance / margin in [0, 1] to red, amber, green, blue.
  function rampColor(THREE, t) {
    const stops = [[0, 0xe0271c], [1 / 3, 0xf2b01e], [2 / 3, 0x2a9d4b], [1, 0x2f6fd6]];
    t = Math.min(Math.max(t, 0), 1);
    for (let i = 1; i < stops.length; ++i) {
      if (t <= stops[i][0]) {
        const u = (t - stops[i - 1][0]) / (stops[i][0] - stops[i - 1][0]);
        return new THREE.Color(stops[i - 1][1]).lerp(new THREE.Color(stops[i][1]), u);
      }
    }
    return new THREE.Color(stops[stops.length - 1][1]);
  }

  // The drawing's coordinates: every point as (p - center) / extent, in
  // doubles, before anything becomes a float32 vertex. Bodies from 1e-23 to
  // 1e39 (the paper's stress cases) then draw alike; the label keeps the
  // data's own numbers.
  function normalize(data) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const body of data.bodies) {
      for (const piece of body.pieces) {
        const q = piece.positions;
        for (let i = 0; i < q.length; ++i) {
          lo[i % 3] = Math.min(lo[i % 3], q[i]);
          hi[i % 3] = Math.max(hi[i % 3], q[i]);
        }
      }
    }
    if (!(lo[0] <= hi[0])) return;  // no vertex at all
    // Halves first: hi - lo may overflow near 1e308.
    const center = [0, 1, 2].map((k) => lo[k] / 2 + hi[k] / 2);
    let extent = Math.max(...[0, 1, 2].map((k) => hi[k] / 2 - lo[k] / 2)) * 2;
    if (!(extent > 0) || !isFinite(extent)) extent = Math.max(...center.map(Math.abs), 1);
    const f = (p) => [0, 1, 2].map((k) => p[k] / extent - center[k] / extent);
    for (const body of data.bodies) {
      for (const piece of body.pieces) {
        const q = piece.positions;
        for (let i = 0; i < q.length; ++i) q[i] = q[i] / extent - center[i % 3] / extent;
      }
    }
    const pair = data.pair;
    if (pair) {
      pair.point_a = f(pair.point_a);
      pair.point_b = f(pair.point_b);
      for (const feature of [pair.feature_a, pair.feature_b]) {
        feature.points = feature.points.map(f);
        feature.face = feature.face.map(f);
      }
    }
    for (const p of data.pairs || []) {
      p.point_a = f(p.point_a);
      p.point_b = f(p.point_b);
    }
  }

  function show(THREE, data) {
    normalize(data);
    const container = document.getElementById('view');
    const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(container.clientWidth, container.clientHeight);
    renderer.setClearColor(0xf4f5f7);
    container.appendChild(renderer.domElement);

    const scene = new THREE.Scene();
    const camera = new THREE.PerspectiveCamera(40, container.clientWidth / container.clientHeight, 0.01, 100);
    scene.add(new THREE.AmbientLight(0xffffff, 1.2));
    const light = new THREE.DirectionalLight(0xffffff, 2.0);
    camera.add(light);
    light.position.set(1, 2, 3);
    scene.add(camera);

    // The bounding box of everything drawn frames the camera.
    const box = new THREE.Box3();
    for (const body of data.bodies) {
      for (const piece of body.pieces) {
        for (let i = 0; i < piece.positions.length; i += 3) {
          box.expandByPoint(new THREE.Vector3(piece.positions[i], piece.positions[i + 1], piece.positions[i + 2]));
        }
      }
    }
    const center = box.getCenter(new THREE.Vector3());
    const size = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-300);

    const wireframe = document.getElementById('wireframe');
    // page.html#wireframe opens with the faces hidden (a link can say so).
    if (window.location.hash === '#wireframe') wireframe.checked = true;
    const faceMeshes = [];
    const colors = data.kind === 'pair' ? [COLOR_A, COLOR_B] : null;
    data.bodies.forEach((body, i) => {
      const color = colors ? colors[i] : new THREE.Color().setHSL((i * 0.618) % 1, 0.15, 0.6);
      for (const piece of body.pieces) {
        for (const o of pieceObjects(THREE, piece, color, wireframe.checked, colors ? 0.55 : 0.3)) {
          if (o.userData.faces) faceMeshes.push(o);
          scene.add(o);
        }
      }
    });

    document.getElementById('title').textContent = data.title;
    if (data.kind === 'pair') showPair(THREE, data, scene, size);
    else showScene(THREE, data, scene, size);

    const render = () => renderer.render(scene, camera);
    const control = OrbitControl(THREE, camera, renderer.domElement, render);
    control.frame(center, size / 2, data.kind === 'pair' ? data.pair.normal : null);
    wireframe.addEventListener('change', () => {
      for (const m of faceMeshes) m.visible = !wireframe.checked;
      render();
    });
    window.addEventListener('resize', () => {
      camera.aspect = container.clientWidth / container.clientHeight;
      camera.updateProjectionMatrix();
      renderer.setSize(container.clientWidth, container.clientHeight);
      render();
    });
    render();
  }

  function showPair(THREE, data, scene, size) {
    const pair = data.pair;
    const depth = pair.signed_distance < 0;
    const label = document.getElementById('label');
    label.textContent = depth ? 'penetration depth ' + num(-pair.signed_distance)
                              : 'distance ' + num(pair.distance);
    label.dataset.value = num(depth ? -pair.signed_distance : pair.distance);
    // A time-of-impact answer carries no bounds (null in the data).
    const bounded = pair.signed_lower_bound !== null && pair.signed_upper_bound !== null;
    document.getElementById('certificate').textContent = (bounded
        ? 'certificate: ' + num(pair.signed_lower_bound) + ' \u2264 signed distance \u2264 ' +
          num(pair.signed_upper_bound)
        : 'signed distance ' + num(pair.signed_distance) + ', no bounds in this answer') +
        '  (' + pair.status + ')';
    const names = data.bodies.map((b) => b.name + (b.radius > 0 ? ' (radius ' + num(b.radius) + ')' : ''));
    document.getElementById('detail').textContent =
        'A: ' + names[0] + ', witness ' + pair.feature_a.type +
        (pair.feature_a.piece >= 0 ? ' of piece ' + pair.feature_a.piece : '') +
        ';  B: ' + names[1] + ', witness ' + pair.feature_b.type +
        (pair.feature_b.piece >= 0 ? ' of piece ' + pair.feature_b.piece : '');
    document.getElementById('legend').innerHTML =
        '<span class="swatch" style="background:#3b7dd8"></span>A' +
        '<span class="swatch" style="background:#e08a1e"></span>B' +
        '<span class="swatch" style="background:#d81b60"></span>witness features' +
        '<span class="swatch" style="background:#111"></span>closest points' +
        '<span class="swatch" style="background:#2a9d4b"></span>normal';

    for (const f of [pair.feature_a, pair.feature_b]) {
      for (const o of witnessObjects(THREE, f, size)) scene.add(o);
    }
    scene.add(ball(THREE, pair.point_a, size * 0.01, COLOR_SEGMENT));
    scene.add(ball(THREE, pair.point_b, size * 0.01, COLOR_SEGMENT));
    scene.add(rod(THREE, pair.point_a, pair.point_b, size * 0.003, COLOR_SEGMENT));
    // The normal, from A towards B, drawn from A's closest point: it runs
    // along the segment when the bodies are apart, and past it.
    const n = new THREE.Vector3(...pair.normal);
    if (n.lengthSq() > 0) {
      // At least the segment's length, drawn over the bodies (no depth
      // test) so that B's faces do not hide it.
      const segment = new THREE.Vector3(...pair.point_a).distanceTo(new THREE.Vector3(...pair.point_b));
      const length = Math.max(size * 0.15, segment * 1.25);
      const arrow = new THREE.ArrowHelper(n.normalize(), new THREE.Vector3(...pair.point_a), length,
                                          COLOR_NORMAL, size * 0.04, size * 0.02);
      arrow.traverse((o) => {
        if (o.material) o.material.depthTest = false;
        o.renderOrder = 10;
      });
      scene.add(arrow);
    }
  }

  function showScene(THREE, data, scene, size) {
    const margin = data.margin;
    const label = document.getElementById('label');
    label.textContent = data.pairs.length + ' close pair' + (data.pairs.length === 1 ? '' : 's') +
        ' within margin ' + num(margin) + ' among ' + data.bodies.length + ' bodies';
    let nearest = null;
    for (const p of data.pairs) if (nearest === null || p.distance < nearest.distance) nearest = p;
    document.getElementById('certificate').textContent = nearest === null ? '' :
        'nearest: bodies ' + nearest.a + ' and ' + nearest.b + ', distance ' + num(nearest.distance) +
        ' (' + nearest.status + ')';
    document.getElementById('legend').innerHTML =
        'pair distance: 0<span class="ramp"></span>' + num(margin);
    for (const p of data.pairs) {
      const color = rampColor(THREE, margin > 0 ? p.distance / margin : 0);
      scene.add(rod(THREE, p.point_a, p.point_b, size * 0.004, color));
      scene.add(ball(THREE, p.point_a, size * 0.007, color));
      scene.add(ball(THREE, p.point_b, size * 0.007, color));
    }
  }

  try {
    const data = JSON.parse(document.getElementById('proxima-data').textContent);
    const source = document.getElementById('three-source').textContent;
    const url = URL.createObjectURL(new Blob([source], { type: 'text/javascript' }));
    import(url).then((THREE) => {
      URL.revokeObjectURL(url);
      show(THREE, data);
      document.body.dataset.rendered = 'yes';
    }).catch(report);
  } catch (error) {
    report(error);
  }
})();
