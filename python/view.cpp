// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: proxima.view() and proxima.view_scene(), the viewer's page from
// Python. The page is the one `proxima view` writes, from the same writer
// (viewer/viewer.h); this file only converts the arguments, writes the file
// and, in a notebook, shows the page inline (an <iframe srcdoc>, so that its
// scripts run apart from the notebook's).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "convert.h"
#include "proxima/query/body_distance.h"
#include "proxima/scene/scene.h"
#include "viewer.h"

namespace proxima::python {
namespace {

// Writes the page to `path` (str or os.PathLike) through Python's open(), so
// that a bad path raises the usual OSError.
void write_page(const std::string& page, const py::object& path) {
  py::object file =
      py::module_::import("builtins")
          .attr("open")(path, "w", py::arg("encoding") = "utf-8", py::arg("newline") = "");
  try {
    file.attr("write")(page);
  } catch (...) {
    file.attr("close")();
    throw;
  }
  file.attr("close")();
}

// True when an IPython kernel (Jupyter) is running this interpreter; a
// terminal IPython has no kernel and gets no inline page.
bool in_notebook() {
  py::object ipython;
  try {
    ipython = py::module_::import("IPython");
  } catch (const py::error_already_set&) {
    return false;
  }
  const py::object shell = ipython.attr("get_ipython")();
  return !shell.is_none() && py::hasattr(shell, "kernel");
}

void show_inline(const std::string& page, int height) {
  const py::object display = py::module_::import("IPython.display");
  const std::string quoted =
      py::module_::import("html").attr("escape")(page, true).cast<std::string>();
  const std::string frame = "<iframe srcdoc=\"" + quoted +
                            "\" style=\"width: 100%; height: " + std::to_string(height) +
                            "px; border: 0\"></iframe>";
  display.attr("display")(display.attr("HTML")(frame));
}

// path, then inline (None: when a notebook is running), then the page back.
std::string deliver(std::string page, const py::object& path, const py::object& show, int height) {
  if (!path.is_none()) write_page(page, path);
  const bool inline_page = show.is_none() ? in_notebook() : show.cast<bool>();
  if (inline_page) show_inline(page, height);
  return page;
}

}  // namespace

void bind_view(py::module_& m) {
  m.def(
      "view",
      [](py::object a, py::object b, py::object pose_a, py::object pose_b, py::object path,
         const std::string& title, const std::string& name_a, const std::string& name_b,
         py::object show, int height) {
        const viewer::ShownBody shown_a{name_a, to_body(a, "a"), to_pose(pose_a, "pose_a")};
        const viewer::ShownBody shown_b{name_b, to_body(b, "b"), to_pose(pose_b, "pose_b")};
        std::string page;
        {
          py::gil_scoped_release release;
          const BodyResult r = distance(shown_a.body, shown_a.pose, shown_b.body, shown_b.pose);
          page = viewer::pair_page(shown_a, shown_b, r, viewer::answer_of(r),
                                   title.empty() ? name_a + " and " + name_b : title);
        }
        return deliver(std::move(page), path, show, height);
      },
      py::arg("a"), py::arg("b"), py::arg("pose_a") = py::none(), py::arg("pose_b") = py::none(),
      py::arg("path") = py::none(), py::arg("title") = "", py::arg("name_a") = "a",
      py::arg("name_b") = "b", py::arg("inline") = py::none(), py::arg("height") = 480,
      "The page of `proxima view` for two bodies: one self-contained HTML page (three.js "
      "inline, no network) showing a and b (ConvexPolytope, CompoundBody or Body) at pose_a and "
      "pose_b (None, a Pose, a 4x4 matrix, a (quaternion, translation) pair ...), their closest "
      "points joined by a segment, the witness features, the normal, the distance or "
      "penetration depth and its certificate (docs/viewer.md). Writes it to path (str or "
      "os.PathLike) when given; shows it inline when inline is True, or when None and a "
      "Jupyter kernel is running (IPython.display, an iframe `height` pixels high). Returns "
      "the page's HTML. RuntimeError when the build had no three.js (scripts/setup installs "
      "it).");

  m.def(
      "view_scene",
      [](std::vector<py::object> bodies, std::vector<py::object> poses, double margin,
         py::object path, const std::string& title, py::object show, int height) {
        if (bodies.size() != poses.size()) {
          throw InvalidInput("view_scene: " + std::to_string(bodies.size()) + " bodies but " +
                             std::to_string(poses.size()) + " poses");
        }
        SceneOptions options;
        options.margin = margin;
        std::vector<viewer::ShownBody> shown;
        shown.reserve(bodies.size());
        for (std::size_t i = 0; i < bodies.size(); ++i) {
          const std::string name = "bodies[" + std::to_string(i) + "]";
          shown.push_back({"body " + std::to_string(i), to_body(bodies[i], name.c_str()),
                           to_pose(poses[i], "poses[" + std::to_string(i) + "]")});
          if (shown.back().body.radius() != 0.0 || shown.back().body.kind() == Body::Kind::mesh)
            throw InvalidInput(name +
                               ": the scene view takes a ConvexPolytope or a CompoundBody (no "
                               "radius, no mesh)");
        }
        std::string page;
        {
          py::gil_scoped_release release;
          Scene scene(options);  // checks the margin
          std::vector<BodyId> ids;
          for (const viewer::ShownBody& s : shown) {
            ids.push_back(s.body.kind() == Body::Kind::convex
                              ? scene.add(s.body.convex(), s.pose)
                              : scene.add(s.body.compound(), s.pose));
          }
          std::vector<viewer::ScenePair> pairs;
          for (const ClosePair& p : scene.step()) {
            int a = -1;
            int b = -1;
            for (std::size_t i = 0; i < ids.size(); ++i) {
              if (ids[i] == p.a) a = static_cast<int>(i);
              if (ids[i] == p.b) b = static_cast<int>(i);
            }
            pairs.push_back({a, b, p.result});
          }
          page = viewer::scene_page(shown, pairs, margin, title.empty() ? "one scene step" : title);
        }
        return deliver(std::move(page), path, show, height);
      },
      py::arg("bodies"), py::arg("poses"), py::arg("margin"), py::arg("path") = py::none(),
      py::arg("title") = "", py::arg("inline") = py::none(), py::arg("height") = 480,
      "The scene page of `proxima view --scene`: one Scene step of `bodies` (ConvexPolytope or "
      "CompoundBody) at `poses` (one per body) with this margin, every close pair drawn as a "
      "segment between its closest points coloured by its distance. path, inline and height as "
      "for view(). Returns the page's HTML.");
}

}  // namespace proxima::python
