// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The whole public API in one include. Every query here takes world poses
// and answers in the world frame. The layers, lowest first (docs/architecture.md):
//   core/      poses (one rigid-pose contract), the accuracy rules, results, options
//   geometry/  closed-form closest-point kernels, templated on the scalar
//   shape/     convex polytopes, support, compounds, triangle meshes, bodies, primitives
//   query/     distance, signed distance and its gradient, compound and mesh
//              distance, any two bodies, batches
//   motion/    time of impact
//   scene/     many moving bodies
// The file readers are a library of their own (proxima_io, proxima/io.h).
// proxima/detail/ holds the algorithms' internal entry points (B's pose
// relative to A, answers in A's frame) for tests and benchmarks; they are not
// part of the API.
#pragma once

#include "proxima/core/pose.h"
#include "proxima/core/types.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/motion/time_of_impact.h"
#include "proxima/query/batch.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/query/signed_distance.h"
#include "proxima/scene/scene.h"
#include "proxima/shape/body.h"
#include "proxima/shape/compound.h"
#include "proxima/shape/mesh.h"
#include "proxima/shape/polytope.h"
#include "proxima/shape/primitives.h"
#include "proxima/shape/support.h"
