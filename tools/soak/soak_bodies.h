// proxima's soak: a drawn pair of convex bodies, and the episodes of the
// other body kinds (soak_bodies.cpp).
// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <memory>
#include <vector>

#include "soak.h"

namespace proxima::soak {

struct ConvexPair {
  std::vector<Vec3> points_a, points_b;
  std::shared_ptr<const ConvexPolytope> a, b;
  double scale = 0;  // the larger of the two bodies' coordinate magnitudes
  double reach = 0;  // the sum of the two
};
ConvexPair draw_convex_pair(Draw& draw);

void rounded_episode(Context& context);
void compound_episode(Context& context);
void mesh_episode(Context& context);
void toi_episode(Context& context);

}  // namespace proxima::soak
