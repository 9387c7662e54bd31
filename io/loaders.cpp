// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: a file to a convex polytope or to a compound body, with the
// report of how convex the input was (load_convex, load_compound,
// compound_from_cloud; see include/proxima/io.h).
#include <algorithm>
#include <array>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "proxima/io.h"

namespace proxima {

LoadedPolytope load_convex(const std::string& path, const ReadOptions& options) {
  PointCloud cloud = read_points(path, options);
  try {
    ConvexPolytope polytope(cloud.points);
    const int interior = polytope.interior_point_count();
    const bool convex = surface_is_convex(polytope, cloud.points, cloud.triangles);
    return LoadedPolytope{std::move(polytope), static_cast<int>(cloud.points.size()), interior,
                          convex};
  } catch (const FileError&) {
    throw;
  } catch (const InvalidInput& e) {
    throw FileError::in_file(path, e.what());
  }
}

// Compound files: one hull per group. The groups' layout is checked here
// rather than trusted, since a PointCloud may come from a caller, not only
// from the OBJ reader.
LoadedCompound compound_from_cloud(const PointCloud& cloud) {
  const auto point_count = static_cast<std::int64_t>(cloud.points.size());
  if (cloud.points.empty()) throw FileError::in_file(cloud.source, "no points");
  if (cloud.group_names.size() != cloud.group_offsets.size()) {
    throw FileError::in_file(cloud.source, "group names and group offsets differ in number (" +
                                               std::to_string(cloud.group_names.size()) + " and " +
                                               std::to_string(cloud.group_offsets.size()) + ")");
  }
  for (std::size_t t = 0; t < cloud.triangles.size(); ++t) {
    for (const std::int32_t i : cloud.triangles[t]) {
      if (i < 0 || i >= point_count) {
        throw FileError::in_file(cloud.source, "triangle " + std::to_string(t) +
                                                   " has vertex index " + std::to_string(i) +
                                                   ", outside the " + std::to_string(point_count) +
                                                   " points");
      }
    }
  }
  // With faces, groups are ranges of triangles; otherwise of points.
  const bool by_triangles = !cloud.triangles.empty() && !cloud.group_offsets.empty();
  const auto item_count =
      by_triangles ? static_cast<std::int64_t>(cloud.triangles.size()) : point_count;
  const std::size_t groups = std::max<std::size_t>(cloud.group_offsets.size(), 1);
  std::vector<CompoundPiece> pieces;
  std::vector<LoadedPiece> reports;
  pieces.reserve(groups);
  reports.reserve(groups);
  std::vector<std::int32_t> local(by_triangles ? cloud.points.size() : 0,
                                  -1);  // point -> index in the piece
  for (std::size_t g = 0; g < groups; ++g) {
    const bool grouped = !cloud.group_offsets.empty();
    const std::string name = grouped ? cloud.group_names[g] : std::string();
    const std::string label = "group " + std::to_string(g) + " '" + name + "'";
    const std::int64_t begin = grouped ? cloud.group_offsets[g] : 0;
    const std::int64_t end = grouped && g + 1 < groups ? cloud.group_offsets[g + 1] : item_count;
    if ((g == 0 && begin != 0) || begin < 0 || end > item_count || begin >= end) {
      throw FileError::in_file(
          cloud.source, label + ": bad " + (by_triangles ? "triangle" : "point") + " range [" +
                            std::to_string(begin) + ", " + std::to_string(end) + ") of " +
                            std::to_string(item_count) + (by_triangles ? " triangles" : " points") +
                            " (groups must be non-empty, in order, from 0)");
    }
    std::vector<Vec3> own_points;
    std::vector<std::array<std::int32_t, 3>> own_triangles;
    std::span<const Vec3> points;
    std::span<const std::array<std::int32_t, 3>> triangles;
    if (by_triangles) {
      // The vertices the group's faces reference, in order of first reference.
      std::vector<std::int32_t> used;
      for (std::int64_t t = begin; t < end; ++t) {
        std::array<std::int32_t, 3> tri{};
        for (std::size_t k = 0; k < 3; ++k) {
          const auto i = static_cast<std::size_t>(cloud.triangles[static_cast<std::size_t>(t)][k]);
          if (local[i] < 0) {
            local[i] = static_cast<std::int32_t>(own_points.size());
            own_points.push_back(cloud.points[i]);
            used.push_back(static_cast<std::int32_t>(i));
          }
          tri[k] = local[i];
        }
        own_triangles.push_back(tri);
      }
      for (const std::int32_t i : used) local[static_cast<std::size_t>(i)] = -1;
      points = own_points;
      triangles = own_triangles;
    } else {
      points =
          std::span<const Vec3>(cloud.points.data() + begin, static_cast<std::size_t>(end - begin));
      if (!grouped) triangles = cloud.triangles;
    }
    try {
      auto polytope = std::make_shared<const ConvexPolytope>(points);
      const int interior = polytope->interior_point_count();
      const bool convex = surface_is_convex(*polytope, points, triangles);
      reports.push_back({name, static_cast<int>(points.size()), interior, convex});
      pieces.push_back({std::move(polytope), Pose::identity()});
    } catch (const InvalidInput& e) {
      throw FileError::in_file(cloud.source, label + ": " + e.what());
    }
  }
  try {
    return LoadedCompound{CompoundBody(std::move(pieces)), std::move(reports)};
  } catch (const FileError&) {
    throw;
  } catch (const InvalidInput& e) {
    throw FileError::in_file(cloud.source, e.what());
  }
}

LoadedCompound load_compound(const std::string& path, const ReadOptions& options) {
  return compound_from_cloud(read_points(path, options));
}

LoadedMesh mesh_from_cloud(const PointCloud& cloud) {
  if (cloud.points.empty()) throw FileError::in_file(cloud.source, "no points");
  if (cloud.triangles.empty()) {
    const bool faces_unread =
        cloud.format != MeshFormat::obj && cloud.format != MeshFormat::stl_ascii &&
        cloud.format != MeshFormat::stl_binary && cloud.format != MeshFormat::unknown;
    throw FileError::in_file(
        cloud.source,
        std::string("no faces to make a mesh of") +
            (faces_unread ? " (the " + std::string(to_string(cloud.format)) +
                                " reader reads points only; use OBJ or STL for a mesh)"
                          : ": a point cloud has no surface; load it as its hull instead"));
  }
  try {
    TriangleMesh mesh(cloud.points, cloud.triangles);
    const int degenerate = static_cast<int>(mesh.degenerate_triangles().size());
    const bool closed = mesh.is_closed();
    return LoadedMesh{std::move(mesh), static_cast<int>(cloud.points.size()), degenerate, closed};
  } catch (const InvalidInput& e) {
    throw FileError::in_file(cloud.source, e.what());
  }
}

LoadedMesh load_mesh(const std::string& path, const ReadOptions& options) {
  return mesh_from_cloud(read_points(path, options));
}

const char* to_string(LoadAs as) {
  switch (as) {
    case LoadAs::mesh:
      return "mesh";
    case LoadAs::hull:
      return "hull";
    case LoadAs::pieces:
      return "pieces";
  }
  return "?";
}

LoadAs load_as_from_string(std::string_view name) {
  for (const LoadAs as : {LoadAs::mesh, LoadAs::hull, LoadAs::pieces}) {
    if (name == to_string(as)) return as;
  }
  throw InvalidInput("load as '" + std::string(name) +
                     "': expected 'mesh' (the surface as given), 'hull' (the convex hull) or "
                     "'pieces' (one hull per group)");
}

Body load_body(const std::string& path, LoadAs as, const ReadOptions& options) {
  switch (as) {
    case LoadAs::mesh:
      return Body(std::make_shared<const TriangleMesh>(load_mesh(path, options).mesh));
    case LoadAs::hull:
      return Body(std::make_shared<const ConvexPolytope>(load_convex(path, options).polytope));
    case LoadAs::pieces:
      return Body(std::make_shared<const CompoundBody>(load_compound(path, options).body));
  }
  throw InvalidInput("load_body: unknown LoadAs");
}

}  // namespace proxima
