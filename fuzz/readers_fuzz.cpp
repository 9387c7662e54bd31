// libFuzzer target for the mesh readers (include/proxima/io.h).
//
// Every input is read as each format, and sniffed; when points come out,
// their hull is built. Only proxima's InvalidInput (FileError is one) may
// leave a reader or the hull: any other exception, a crash, a sanitizer
// report, an allocation beyond -malloc_limit_mb, a hang, a floating-point
// trap (invalid operation, division by zero), or a broken invariant of the
// result is a bug. Built and run by scripts/fuzz.
#include <array>
#include <cfenv>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "proxima/io.h"
#include "proxima/shape/polytope.h"

namespace {

using proxima::MeshFormat;

constexpr std::array<MeshFormat, 8> kFormats = {
    MeshFormat::obj,       MeshFormat::off,           MeshFormat::stl_ascii, MeshFormat::stl_binary,
    MeshFormat::ply_ascii, MeshFormat::ply_binary_le, MeshFormat::xyz,       MeshFormat::unknown};

void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "readers_fuzz: invariant broken: %s\n", what);
    std::abort();
  }
}

bool is_ply(MeshFormat f) { return f == MeshFormat::ply_ascii || f == MeshFormat::ply_binary_le; }

void check_cloud(const proxima::PointCloud& cloud, MeshFormat asked) {
  require(!cloud.points.empty(), "a cloud that was read has points");
  require(cloud.source == "fuzz", "source is the name given");
  require(cloud.format != MeshFormat::unknown, "the format read is known");
  require(asked == MeshFormat::unknown || cloud.format == asked ||
              (is_ply(asked) && is_ply(cloud.format)),
          "the format read is the one asked for");
  for (const proxima::Vec3& p : cloud.points) require(p.allFinite(), "points are finite");
  for (const auto& t : cloud.triangles) {
    for (const std::int32_t i : t)
      require(i >= 0 && static_cast<std::size_t>(i) < cloud.points.size(),
              "triangle indices in range");
  }
  require(cloud.group_names.size() == cloud.group_offsets.size(), "one offset per group name");
  // Groups range over the triangles when there are any, else over the points.
  const std::size_t items = cloud.triangles.empty() ? cloud.points.size() : cloud.triangles.size();
  for (std::size_t g = 0; g < cloud.group_offsets.size(); ++g) {
    require((cloud.group_offsets[g] == 0) == (g == 0), "groups start at 0");
    require(static_cast<std::size_t>(cloud.group_offsets[g]) < items, "groups are non-empty");
    require(g == 0 || cloud.group_offsets[g - 1] < cloud.group_offsets[g],
            "group offsets increase");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The unit tests run with these traps on; so does the fuzzer.
  feenableexcept(FE_INVALID | FE_DIVBYZERO);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  for (const MeshFormat format : kFormats) {
    try {
      const proxima::PointCloud cloud = proxima::read_points_from_memory(bytes, format, "fuzz");
      check_cloud(cloud, format);
      const proxima::ConvexPolytope polytope(cloud.points);
      require(polytope.vertex_count() >= 1, "a hull has a vertex");
      require(polytope.vertex_count() + polytope.interior_point_count() ==
                  static_cast<int>(cloud.points.size()),
              "every input point is a hull vertex or counted as interior");
      proxima::surface_is_convex(polytope, cloud.points, cloud.triangles);
      if (!cloud.group_offsets.empty()) {  // OBJ groups: one convex piece each
        const proxima::LoadedCompound compound = proxima::compound_from_cloud(cloud);
        require(compound.body.piece_count() == static_cast<int>(cloud.group_offsets.size()),
                "one compound piece per group");
      }
    } catch (const proxima::InvalidInput&) {
      // Refused input: the expected outcome for most mutants.
    }
  }
  return 0;
}
