// A robot from its URDF, built and run by `make test`: the Franka Emika
// Panda (examples/data/panda: URDF, SRDF and collision meshes) with a table,
// its minimum signed distance and the gradient of it with respect to the
// joints, along a short trajectory. The robot's query state keeps each
// pair's cache from one configuration to the next (tracking); each answer
// is checked against a cold query (no state), and a mismatch returns 1.
//
//   robot_urdf [panda folder]   (default: examples/data/panda)
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/urdf.h>
#include <proxima/shape/primitives.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

int run(const std::string& dir) {
  const proxima::Robot robot = proxima::load_robot(dir + "/panda.urdf", dir + "/panda.srdf");
  std::printf("%s: %d joints, %zu collision geometries, %zu self pairs tested\n",
              robot.name().c_str(), robot.dof(), robot.geometries().size(),
              robot.self_pairs().size());

  const std::vector<proxima::Obstacle> table = {proxima::Obstacle(
      proxima::make_box({0.25, 0.5, 0.02}), proxima::Pose::from_translation({0.75, 0, 0.18}))};
  proxima::RobotQueryOptions options;
  options.gradients = true;
  proxima::RobotQueryState state;  // cold; kept along the trajectory

  // From the SRDF's "default" pose, joint 2 leaning forward, joint 6 folding the hand towards
  // link5.
  std::vector<double> q = {0, -0.785, 0, -2.356, 0, 1.571, 0.785, 0.01};
  int mismatches = 0;
  for (int step = 0; step < 10; ++step) {
    q[1] += 0.08;
    q[5] -= 0.12;
    const proxima::RobotDistances r = proxima::robot_distances(robot, q, table, options, &state);
    const proxima::RobotDistances cold = proxima::robot_distances(robot, q, table, options);
    if (std::abs(r.min_signed_distance - cold.min_signed_distance) > 1e-9) ++mismatches;
    const auto& a = robot.geometries()[static_cast<std::size_t>(r.closest.geometry_a)];
    const std::string b =
        r.closest.environment
            ? std::string("the table")
            : robot
                  .links()[static_cast<std::size_t>(
                      robot.geometries()[static_cast<std::size_t>(r.closest.geometry_b)].link)]
                  .name;
    std::printf("step %d: %.4f m between %s and %s, d/dq6 %.4f\n", step, r.min_signed_distance,
                robot.links()[static_cast<std::size_t>(a.link)].name.c_str(), b.c_str(),
                r.closest.gradient[5]);
  }
  std::printf("%d mismatches against cold queries\n", mismatches);
  return mismatches == 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  try {
    return run(argc > 1 ? argv[1] : "examples/data/panda");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robot_urdf: %s\n", e.what());
    return 1;
  }
}
