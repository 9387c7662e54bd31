// Robots from their URDF (proxima/robot/): the loader against hand-checked
// link poses, forward kinematics against an independent implementation
// written out here, point Jacobians and pair gradients against central
// finite differences, every query against the slow path (a cold distance()
// on every enabled pair, at poses from the independent kinematics), and
// clear errors for bad descriptions.
//
// The real descriptions are read from ../shared/robots relative to the
// repository root (the Panda, a UR5, Talos); the tests that need them skip
// when it is absent.
#include <gtest/gtest.h>
#include <proxima/robot/robot_distance.h>
#include <proxima/robot/urdf.h>
#include <proxima/shape/primitives.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace {

using proxima::Pose;
using proxima::Robot;
using proxima::Vec3;
using Mat3 = proxima::Mat3;

const std::string kRobots = std::string(PROXIMA_SOURCE_DIR) + "/../shared/robots";
const std::string kPandaUrdf = kRobots + "/robots/panda_description/urdf/panda.urdf";
const std::string kPandaSrdf = kRobots + "/robots/panda_description/srdf/panda.srdf";

bool have_robots() { return std::filesystem::exists(kPandaUrdf); }

proxima::RobotLoadOptions packages() {
  proxima::RobotLoadOptions options;
  options.package_dirs = {"example-robot-data=" + kRobots};
  return options;
}

const Robot& panda() {
  static const Robot robot = proxima::load_robot(kPandaUrdf, kPandaSrdf, packages());
  return robot;
}

// The Panda's kinematics, written out from panda.urdf independently of the
// loader: URDF rpy is R = Rz(yaw) Ry(pitch) Rx(roll); every arm joint turns
// about its z axis; the fingers slide along +y and -y (the second mimics the
// first).
Mat3 rpy(double roll, double pitch, double yaw) {
  const auto rx = [](double a) {
    Mat3 m;
    m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
    return m;
  };
  const auto ry = [](double a) {
    Mat3 m;
    m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
    return m;
  };
  const auto rz = [](double a) {
    Mat3 m;
    m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
    return m;
  };
  return rz(yaw) * ry(pitch) * rx(roll);
}

struct PandaPoses {
  std::array<Pose, 8> arm;  // link0 .. link7
  Pose link8, hand, left, right;
};

PandaPoses panda_fk_by_hand(const std::vector<double>& q) {
  constexpr double h = std::numbers::pi / 2;
  const std::array<Pose, 7> origins = {{
      {rpy(0, 0, 0), Vec3(0, 0, 0.333)},
      {rpy(-h, 0, 0), Vec3(0, 0, 0)},
      {rpy(h, 0, 0), Vec3(0, -0.316, 0)},
      {rpy(h, 0, 0), Vec3(0.0825, 0, 0)},
      {rpy(-h, 0, 0), Vec3(-0.0825, 0.384, 0)},
      {rpy(h, 0, 0), Vec3(0, 0, 0)},
      {rpy(h, 0, 0), Vec3(0.088, 0, 0)},
  }};
  PandaPoses p;
  for (int i = 0; i < 7; ++i) {
    const Pose turn(rpy(0, 0, q[static_cast<std::size_t>(i)]), Vec3::Zero());
    p.arm[static_cast<std::size_t>(i + 1)] =
        p.arm[static_cast<std::size_t>(i)] * origins[static_cast<std::size_t>(i)] * turn;
  }
  p.link8 = p.arm[7] * Pose(Mat3::Identity(), Vec3(0, 0, 0.107));
  p.hand = p.link8 * Pose(rpy(0, 0, -std::numbers::pi / 4), Vec3::Zero());
  p.left = p.hand * Pose(Mat3::Identity(), Vec3(0, q[7], 0.0584));
  p.right = p.hand * Pose(Mat3::Identity(), Vec3(0, -q[7], 0.0584));
  return p;
}

// The by-hand pose of a Panda link by name.
Pose by_hand(const PandaPoses& p, const std::string& link) {
  if (link == "panda_link8") return p.link8;
  if (link == "panda_hand") return p.hand;
  if (link == "panda_hand_tcp") return p.hand * Pose(Mat3::Identity(), Vec3(0, 0, 0.1034));
  if (link == "panda_leftfinger") return p.left;
  if (link == "panda_rightfinger") return p.right;
  return p.arm[static_cast<std::size_t>(link.back() - '0')];
}

double pose_gap(const Pose& a, const Pose& b) {
  return std::max((a.rotation - b.rotation).cwiseAbs().maxCoeff(),
                  (a.translation - b.translation).cwiseAbs().maxCoeff());
}

std::vector<double> random_q(const Robot& robot, std::mt19937_64& rng) {
  const Eigen::VectorXd lo = robot.lower_limits(), hi = robot.upper_limits();
  std::vector<double> q(static_cast<std::size_t>(robot.dof()));
  for (int v = 0; v < robot.dof(); ++v) {
    const double a = std::isfinite(lo[v]) ? lo[v] : -std::numbers::pi;
    const double b = std::isfinite(hi[v]) ? hi[v] : std::numbers::pi;
    q[static_cast<std::size_t>(v)] = std::uniform_real_distribution<double>(a, b)(rng);
  }
  return q;
}

// A table under the arm and a shelf beside it.
std::vector<proxima::Obstacle> table_and_shelf() {
  std::vector<proxima::Obstacle> obstacles;
  obstacles.emplace_back(proxima::make_box(Vec3(0.6, 0.6, 0.02)),
                         Pose(Mat3::Identity(), Vec3(0.3, 0, -0.021)), "table");
  obstacles.emplace_back(proxima::make_box(Vec3(0.2, 0.4, 0.01)),
                         Pose(Mat3::Identity(), Vec3(0.5, 0, 0.4)), "shelf");
  return obstacles;
}

TEST(RobotLoad, PandaFlangeAtHandCheckedPoseWithAllJointsAtZero) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  EXPECT_EQ(robot.name(), "panda");
  ASSERT_EQ(robot.dof(), 8);  // seven arm joints and one finger (the other mimics it)
  const std::vector<std::string> names = robot.variable_names();
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(names[static_cast<std::size_t>(i)], "panda_joint" + std::to_string(i + 1));
  }
  EXPECT_EQ(names[7], "panda_finger_joint1");
  const std::vector<Pose> poses = robot.forward_kinematics(std::vector<double>(8, 0.0));
  const Pose& flange = poses[static_cast<std::size_t>(robot.link_index("panda_link8"))];
  // Hand-checked: z = 0.333 + 0.316 + 0.384 - 0.107, x = 0.0825 - 0.0825 + 0.088.
  EXPECT_NEAR(flange.translation.x(), 0.088, 1e-12);
  EXPECT_NEAR(flange.translation.y(), 0.0, 1e-12);
  EXPECT_NEAR(flange.translation.z(), 0.926, 1e-12);
  // The flange points down at q = 0.
  EXPECT_NEAR(flange.rotation(2, 2), -1.0, 1e-12);
  // 17 collision elements: a mesh on each of link0..7 and the hand, four
  // boxes on each finger.
  EXPECT_EQ(robot.geometries().size(), 17u);
  EXPECT_EQ(robot.link_geometries(robot.link_index("panda_leftfinger")).size(), 4u);
}

TEST(RobotKinematics, PandaForwardKinematicsMatchesTheIndependentTable) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  std::mt19937_64 rng(27);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<double> q = random_q(robot, rng);
    const std::vector<Pose> poses = robot.forward_kinematics(q);
    const PandaPoses expected = panda_fk_by_hand(q);
    for (std::size_t l = 0; l < robot.links().size(); ++l) {
      EXPECT_LT(pose_gap(poses[l], by_hand(expected, robot.links()[l].name)), 1e-12)
          << robot.links()[l].name;
    }
  }
}

TEST(RobotKinematics, PointJacobianMatchesCentralDifferences) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  std::mt19937_64 rng(2027);
  // Central differences of a smooth map err by O(h^2) (~1e-12 here) plus
  // rounding of O(u / h) (~1e-10).
  constexpr double kStep = 1e-6, kTolerance = 1e-8;
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<double> q = random_q(robot, rng);
    const std::vector<Pose> poses = robot.forward_kinematics(q);
    for (const char* name : {"panda_link4", "panda_hand", "panda_rightfinger"}) {
      const std::int32_t link = robot.link_index(name);
      const Vec3 local(0.03, -0.02, 0.05);
      const Vec3 point = poses[static_cast<std::size_t>(link)].apply(local);
      const auto jacobian = robot.point_jacobian(poses, link, point);
      for (int v = 0; v < robot.dof(); ++v) {
        std::vector<double> up = q, down = q;
        up[static_cast<std::size_t>(v)] += kStep;
        down[static_cast<std::size_t>(v)] -= kStep;
        const Vec3 difference =
            (robot.forward_kinematics(up)[static_cast<std::size_t>(link)].apply(local) -
             robot.forward_kinematics(down)[static_cast<std::size_t>(link)].apply(local)) /
            (2 * kStep);
        EXPECT_LT((jacobian.col(v) - difference).norm(), kTolerance) << name << " column " << v;
      }
    }
  }
}

TEST(RobotPairs, AdjacentAndSrdfPairsAreExcluded) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  const auto link = [&](const char* n) { return robot.link_index(n); };
  EXPECT_FALSE(robot.link_pair_enabled(link("panda_link0"), link("panda_link1")));
  EXPECT_FALSE(robot.link_pair_enabled(link("panda_link1"), link("panda_link3")));  // SRDF
  EXPECT_TRUE(robot.link_pair_enabled(link("panda_link1"), link("panda_link5")));
  EXPECT_TRUE(robot.link_pair_enabled(link("panda_link2"), link("panda_hand")));
  // Without the SRDF: link7 and the hand are adjacent through link8, which
  // has no geometry; link1 and link3 are tested.
  const Robot bare = proxima::load_robot(kPandaUrdf, "", packages());
  EXPECT_FALSE(
      bare.link_pair_enabled(bare.link_index("panda_link7"), bare.link_index("panda_hand")));
  EXPECT_FALSE(
      bare.link_pair_enabled(bare.link_index("panda_hand"), bare.link_index("panda_leftfinger")));
  EXPECT_TRUE(
      bare.link_pair_enabled(bare.link_index("panda_link1"), bare.link_index("panda_link3")));
  // The self pairs are the geometry pairs of enabled link pairs, each once.
  std::size_t expected = 0;
  for (std::size_t a = 0; a < robot.geometries().size(); ++a) {
    for (std::size_t b = a + 1; b < robot.geometries().size(); ++b) {
      expected += robot.link_pair_enabled(robot.geometries()[a].link, robot.geometries()[b].link);
    }
  }
  EXPECT_EQ(robot.self_pairs().size(), expected);
  EXPECT_LT(robot.self_pairs().size(), bare.self_pairs().size());
}

// The slow path: a cold distance() on every enabled pair at poses from the
// independent kinematics.
struct SlowAnswer {
  double min_self = std::numeric_limits<double>::infinity();
  double min_environment = std::numeric_limits<double>::infinity();
  struct Close {
    int a, b;  // geometries, or a geometry and an obstacle
    bool environment;
    double signed_distance;
  };
  std::vector<Close> close;
};

SlowAnswer slow_panda(const Robot& robot, const std::vector<double>& q,
                      const std::vector<proxima::Obstacle>& obstacles, double margin) {
  const PandaPoses by = panda_fk_by_hand(q);
  const auto pose_of = [&](std::size_t g) {
    const proxima::RobotGeometry& geometry = robot.geometries()[g];
    return by_hand(by, robot.links()[static_cast<std::size_t>(geometry.link)].name) *
           geometry.origin;
  };
  SlowAnswer slow;
  for (std::size_t a = 0; a < robot.geometries().size(); ++a) {
    for (std::size_t b = a + 1; b < robot.geometries().size(); ++b) {
      if (!robot.link_pair_enabled(robot.geometries()[a].link, robot.geometries()[b].link))
        continue;
      const double sd = proxima::distance(robot.geometries()[a].body, pose_of(a),
                                          robot.geometries()[b].body, pose_of(b))
                            .signed_distance();
      slow.min_self = std::min(slow.min_self, sd);
      if (sd <= margin) slow.close.push_back({static_cast<int>(a), static_cast<int>(b), false, sd});
    }
  }
  for (std::size_t a = 0; a < robot.geometries().size(); ++a) {
    for (std::size_t o = 0; o < obstacles.size(); ++o) {
      const double sd = proxima::distance(robot.geometries()[a].body, pose_of(a), obstacles[o].body,
                                          obstacles[o].pose)
                            .signed_distance();
      slow.min_environment = std::min(slow.min_environment, sd);
      if (sd <= margin) slow.close.push_back({static_cast<int>(a), static_cast<int>(o), true, sd});
    }
  }
  return slow;
}

// Tracked and cold answers agree with the slow path within the accuracy
// standard at the robot's scale (R ~ 1 m: 64 u R ~ 1e-14) plus the
// 1e-12 relative tolerance of the queries.
constexpr double kAgreement = 1e-10;

TEST(RobotDistance, EveryQueryMatchesTheSlowPathAlongATrajectory) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  const std::vector<proxima::Obstacle> obstacles = table_and_shelf();
  std::mt19937_64 rng(31);
  std::vector<double> q = random_q(robot, rng), target = random_q(robot, rng);
  proxima::RobotQueryState state;
  proxima::RobotQueryOptions options;
  options.margin = 0.05;
  int overlapping = 0, pruned = 0, compared_pairs = 0;
  for (int step = 0; step < 120; ++step) {
    if (step % 10 == 0) target = random_q(robot, rng);
    for (std::size_t v = 0; v < q.size(); ++v) q[v] += 0.2 * (target[v] - q[v]);
    const proxima::RobotDistances fast =
        proxima::robot_distances(robot, q, obstacles, options, &state);
    const SlowAnswer slow = slow_panda(robot, q, obstacles, options.margin);
    EXPECT_NEAR(fast.min_self, slow.min_self, kAgreement) << "step " << step;
    EXPECT_NEAR(fast.min_environment, slow.min_environment, kAgreement) << "step " << step;
    EXPECT_NEAR(fast.min_signed_distance, std::min(slow.min_self, slow.min_environment),
                kAgreement);
    EXPECT_NEAR(fast.closest.signed_distance(), fast.min_signed_distance, 0.0);
    // The same close pairs, up to pairs at the margin within the agreement.
    std::size_t matched = 0;
    for (const SlowAnswer::Close& c : slow.close) {
      for (const proxima::RobotPairResult& pair : fast.close_pairs) {
        if (pair.geometry_a == c.a && pair.geometry_b == c.b && pair.environment == c.environment &&
            std::abs(pair.signed_distance() - c.signed_distance) <= kAgreement) {
          ++matched;
          break;
        }
      }
      overlapping += c.signed_distance < 0;
    }
    EXPECT_EQ(matched, slow.close.size()) << "step " << step;
    EXPECT_EQ(fast.close_pairs.size(), slow.close.size()) << "step " << step;
    compared_pairs += static_cast<int>(slow.close.size());
    pruned +=
        static_cast<int>(robot.self_pairs().size() + robot.geometries().size() * obstacles.size()) -
        fast.pairs_queried;
  }
  // The trajectory met close and overlapping pairs, and the pruning skipped
  // pairs (so both of its sides were exercised).
  EXPECT_GT(compared_pairs, 50);
  EXPECT_GT(overlapping, 0);
  EXPECT_GT(pruned, 0);
}

// minimum_only queries fewer pairs (an overlapping pair that cannot be the
// deepest is skipped) and must still give the slow path's minima, tracked
// along a trajectory through collisions, with the closest pair's gradient
// that of the full query.
TEST(RobotDistance, MinimumOnlyMatchesTheSlowPathAlongATrajectory) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  const std::vector<proxima::Obstacle> obstacles = table_and_shelf();
  std::mt19937_64 rng(37);
  std::vector<double> q = random_q(robot, rng), target = random_q(robot, rng);
  proxima::RobotQueryState state, full_state;
  proxima::RobotQueryOptions options, full;
  options.minimum_only = true;
  options.gradients = true;
  options.margin = 0.05;  // not read
  full.gradients = true;
  int colliding = 0, fewer = 0;
  for (int step = 0; step < 120; ++step) {
    if (step % 10 == 0) target = random_q(robot, rng);
    for (std::size_t v = 0; v < q.size(); ++v) q[v] += 0.2 * (target[v] - q[v]);
    const proxima::RobotDistances fast =
        proxima::robot_distances(robot, q, obstacles, options, &state);
    const proxima::RobotDistances reference =
        proxima::robot_distances(robot, q, obstacles, full, &full_state);
    const SlowAnswer slow = slow_panda(robot, q, obstacles, 0.0);
    EXPECT_NEAR(fast.min_self, slow.min_self, kAgreement) << "step " << step;
    EXPECT_NEAR(fast.min_environment, slow.min_environment, kAgreement) << "step " << step;
    EXPECT_NEAR(fast.min_signed_distance, std::min(slow.min_self, slow.min_environment),
                kAgreement);
    EXPECT_TRUE(fast.close_pairs.empty());
    if (fast.closest.geometry_a == reference.closest.geometry_a &&
        fast.closest.geometry_b == reference.closest.geometry_b &&
        fast.closest.environment == reference.closest.environment) {
      EXPECT_LE((fast.closest.gradient - reference.closest.gradient).cwiseAbs().maxCoeff(),
                kAgreement)
          << "step " << step;
    }
    colliding += fast.min_signed_distance < 0;
    fewer += fast.pairs_queried < reference.pairs_queried;
  }
  EXPECT_GT(colliding, 5);
  EXPECT_GT(fewer, 0);
}

TEST(RobotDistance, PairGradientsMatchCentralDifferences) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  const std::vector<proxima::Obstacle> obstacles = table_and_shelf();
  std::mt19937_64 rng(41);
  proxima::RobotQueryOptions options;
  options.margin = 0.1;
  options.gradients = true;
  // Central differences of the pair's signed distance, where its witness
  // features are the same at q and at q +- h e_v (the signed distance is
  // then smooth there): O(h^2) truncation and O(u / h) rounding, far below
  // 1e-6 of the gradient's size.
  constexpr double kStep = 1e-6, kRelative = 1e-6;
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::vector<double> q = random_q(robot, rng);
    const proxima::RobotDistances r = proxima::robot_distances(robot, q, obstacles, options);
    for (const proxima::RobotPairResult& pair : r.close_pairs) {
      ASSERT_TRUE(pair.has_gradient);
      const auto pair_at = [&](const std::vector<double>& at) {
        const std::vector<Pose> poses = robot.forward_kinematics(at);
        const proxima::RobotGeometry& a =
            robot.geometries()[static_cast<std::size_t>(pair.geometry_a)];
        const Pose pose_a = poses[static_cast<std::size_t>(a.link)] * a.origin;
        if (pair.environment) {
          const proxima::Obstacle& o = obstacles[static_cast<std::size_t>(pair.geometry_b)];
          return proxima::distance(a.body, pose_a, o.body, o.pose);
        }
        const proxima::RobotGeometry& b =
            robot.geometries()[static_cast<std::size_t>(pair.geometry_b)];
        return proxima::distance(a.body, pose_a, b.body,
                                 poses[static_cast<std::size_t>(b.link)] * b.origin);
      };
      const auto same_features = [](const proxima::BodyResult& x,
                                    const proxima::BodyResult& y) {
        return x.status == y.status && x.feature_a.vertices == y.feature_a.vertices &&
               x.feature_b.vertices == y.feature_b.vertices &&
               x.feature_a.type == y.feature_a.type && x.feature_b.type == y.feature_b.type;
      };
      Eigen::VectorXd difference(robot.dof());
      bool smooth = true;
      for (int v = 0; v < robot.dof() && smooth; ++v) {
        std::vector<double> up = q, down = q;
        up[static_cast<std::size_t>(v)] += kStep;
        down[static_cast<std::size_t>(v)] -= kStep;
        const proxima::BodyResult u = pair_at(up), d = pair_at(down);
        smooth = same_features(u, pair.result) && same_features(d, pair.result);
        difference[v] = (u.signed_distance() - d.signed_distance()) / (2 * kStep);
      }
      if (!smooth) continue;
      ++checked;
      EXPECT_LT((pair.gradient - difference).norm(), kRelative * std::max(1.0, difference.norm()))
          << "pair " << pair.geometry_a << " " << pair.geometry_b << " env " << pair.environment
          << " sd " << pair.signed_distance() << "\n"
          << pair.gradient.transpose() << "\n"
          << difference.transpose();
    }
  }
  EXPECT_GT(checked, 30);
}

TEST(RobotDistance, BatchMatchesOneQueryPerRow) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  const std::vector<proxima::Obstacle> obstacles = table_and_shelf();
  std::mt19937_64 rng(43);
  proxima::RowMatrixXd q(300, robot.dof());
  for (Eigen::Index k = 0; k < q.rows(); ++k) {
    const std::vector<double> row = random_q(robot, rng);
    for (int v = 0; v < robot.dof(); ++v) q(k, v) = row[static_cast<std::size_t>(v)];
  }
  proxima::RobotQueryOptions options;
  options.gradients = true;
  for (int threads : {1, 2}) {
    const proxima::RobotBatchDistances batch =
        proxima::robot_distances_batch(robot, q, obstacles, options, threads);
    ASSERT_EQ(batch.gradient.rows(), q.rows());
    for (Eigen::Index k = 0; k < q.rows(); ++k) {
      const std::vector<double> row(q.row(k).data(), q.row(k).data() + q.cols());
      const proxima::RobotDistances one = proxima::robot_distances(robot, row, obstacles, options);
      EXPECT_NEAR(batch.min_signed_distance[k], one.min_signed_distance, kAgreement);
      EXPECT_LT((batch.gradient.row(k).transpose() - one.closest.gradient).norm(), 1e-8);
    }
  }
}

TEST(RobotLoad, Ur5AndTalosLoad) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot ur5 =
      proxima::load_robot(kRobots + "/robots/ur_description/urdf/ur5_robot.urdf",
                          kRobots + "/robots/ur_description/srdf/ur5.srdf", packages());
  EXPECT_EQ(ur5.dof(), 6);
  EXPECT_EQ(ur5.geometries().size(), 8u);
  // Talos writes package:///example-robot-data/... (three slashes).
  const Robot talos =
      proxima::load_robot(kRobots + "/robots/talos_data/robots/talos_full_v2.urdf",
                          kRobots + "/robots/talos_data/srdf/talos.srdf", packages());
  EXPECT_EQ(talos.geometries().size(), 52u);
  EXPECT_GT(talos.dof(), 30);
  std::mt19937_64 rng(47);
  const std::vector<double> q = random_q(talos, rng);
  const proxima::RobotDistances r = proxima::robot_distances(talos, q, {});
  EXPECT_TRUE(std::isfinite(r.min_signed_distance));
}

TEST(RobotLoad, MeshModesGiveBodiesOfThatKind) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  proxima::RobotLoadOptions options = packages();
  options.mesh_as = proxima::LoadAs::mesh;
  options.link_mesh_as["panda_link3"] = proxima::LoadAs::hull;
  const Robot robot = proxima::load_robot(kPandaUrdf, kPandaSrdf, options);
  const auto kind_of = [&](const char* link) {
    return robot
        .geometries()[static_cast<std::size_t>(robot.link_geometries(robot.link_index(link))[0])]
        .body.kind();
  };
  EXPECT_EQ(kind_of("panda_link2"), proxima::Body::Kind::mesh);
  EXPECT_EQ(kind_of("panda_link3"), proxima::Body::Kind::convex);
  EXPECT_EQ(kind_of("panda_leftfinger"), proxima::Body::Kind::convex);  // boxes stay boxes
  // A link's surface lies inside its hull: the meshes are never closer.
  std::mt19937_64 rng(53);
  for (int trial = 0; trial < 5; ++trial) {
    const std::vector<double> q = random_q(robot, rng);
    EXPECT_GE(proxima::robot_distances(robot, q, {}).min_self + kAgreement,
              proxima::robot_distances(panda(), q, {}).min_self);
  }
}

// Bad descriptions: the error names the file and the link, joint or URI.
std::string write_urdf(const std::string& name, const std::string& body) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << "<?xml version=\"1.0\"?>\n<robot name=\"bad\">\n" << body << "</robot>\n";
  return path;
}

std::string load_error(const std::string& path, const proxima::RobotLoadOptions& options = {}) {
  try {
    proxima::load_robot(path, "", options);
  } catch (const proxima::InvalidInput& e) {
    return e.what();
  }
  return "no error";
}

TEST(RobotLoad, BadDescriptionsGetErrorsNamingWhatAndWhere) {
  const std::string two_links = R"(<link name="base"/><link name="arm"/>)";
  {
    const std::string path = write_urdf("proxima_robot_floating.urdf", two_links + R"(
      <joint name="free" type="floating"><parent link="base"/><child link="arm"/></joint>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("free"), std::string::npos) << error;
    EXPECT_NE(error.find("floating"), std::string::npos) << error;
  }
  {
    const std::string path = write_urdf("proxima_robot_badtype.urdf", two_links + R"(
      <joint name="j" type="hinge"><parent link="base"/><child link="arm"/></joint>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("proxima_robot_badtype.urdf"), std::string::npos) << error;
    EXPECT_NE(error.find("hinge"), std::string::npos) << error;
  }
  {
    const std::string path = write_urdf("proxima_robot_badnumber.urdf", two_links + R"(
      <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
      <origin xyz="0 0 zero"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("zero"), std::string::npos) << error;
  }
  {
    const std::string path = write_urdf("proxima_robot_missing_mesh.urdf", R"(
      <link name="base"><collision><geometry><mesh filename="no_such.stl"/></geometry></collision></link>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("no_such.stl"), std::string::npos) << error;
  }
  {
    const std::string path = write_urdf("proxima_robot_package.urdf", R"(
      <link name="base"><collision><geometry><mesh filename="package://nowhere/a.stl"/></geometry></collision></link>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("base"), std::string::npos) << error;
    EXPECT_NE(error.find("nowhere"), std::string::npos) << error;
  }
  {
    const std::string path = write_urdf("proxima_robot_mimic.urdf", two_links + R"(
      <link name="tip"/>
      <joint name="a" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="ghost"/></joint>
      <joint name="b" type="fixed"><parent link="arm"/><child link="tip"/></joint>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("\"a\""), std::string::npos) << error;
    EXPECT_NE(error.find("ghost"), std::string::npos) << error;
  }
  {
    const std::string path = write_urdf("proxima_robot_zero_axis.urdf", two_links + R"(
      <joint name="spin" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 0"/></joint>)");
    const std::string error = load_error(path);
    EXPECT_NE(error.find("spin"), std::string::npos) << error;
  }
  EXPECT_NE(load_error("/nonexistent/robot.urdf").find("/nonexistent/robot.urdf"),
            std::string::npos);
}

TEST(RobotDistance, BadQueriesAreRefusedNamingTheProblem) {
  if (!have_robots()) GTEST_SKIP() << kRobots << " absent";
  const Robot& robot = panda();
  const auto error_of = [&](std::vector<double> q, double margin) {
    try {
      proxima::RobotQueryOptions options;
      options.margin = margin;
      proxima::robot_distances(robot, q, {}, options);
    } catch (const proxima::InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of(std::vector<double>(7, 0.0), 0).find("7 entries"), std::string::npos);
  std::vector<double> q(8, 0.0);
  q[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of(q, 0).find("panda_joint4"), std::string::npos);
  EXPECT_NE(error_of(std::vector<double>(8, 0.0), -1).find("margin"), std::string::npos);
  // Regression: a NaN margin reached the check !(margin >= 0), whose ordered
  // comparison raises FE_INVALID, so under the test main's traps the query
  // died of SIGFPE instead of refusing the margin by name.
  EXPECT_NE(error_of(std::vector<double>(8, 0.0), std::numeric_limits<double>::quiet_NaN())
                .find("margin"),
            std::string::npos);
}

// A mimic chain composes its maps: c = 2 b + 1 and b = -a + 0.5 make
// c = -2 a + 2, and the Jacobian carries the multiplier.
TEST(RobotKinematics, MimicChainsComposeAndPrismaticJointsSlide) {
  proxima::RobotDescription d;
  d.name = "chain";
  d.links = {{"base"}, {"a"}, {"b"}, {"c"}};
  const auto joint = [](std::string name, proxima::JointType type, int parent, int child) {
    proxima::RobotJoint j;
    j.name = std::move(name);
    j.type = type;
    j.parent = parent;
    j.child = child;
    j.lower = -10;
    j.upper = 10;
    return j;
  };
  d.joints.push_back(joint("ja", proxima::JointType::prismatic, 0, 1));
  d.joints.back().axis = Vec3(2, 0, 0);  // normalized by Robot
  d.joints.push_back(joint("jb", proxima::JointType::prismatic, 0, 2));
  d.joints.back().mimic = "ja";
  d.joints.back().multiplier = -1;
  d.joints.back().offset = 0.5;
  d.joints.push_back(joint("jc", proxima::JointType::revolute, 0, 3));
  d.joints.back().mimic = "jb";
  d.joints.back().multiplier = 2;
  d.joints.back().offset = 1;
  const Robot robot(d);
  ASSERT_EQ(robot.dof(), 1);
  const std::vector<double> q = {0.3};
  const std::vector<Pose> poses = robot.forward_kinematics(q);
  EXPECT_NEAR(poses[1].translation.x(), 0.3, 1e-15);
  EXPECT_NEAR(poses[2].translation.z(), 0.2, 1e-15);  // b = -0.3 + 0.5 along z (default axis)
  const double angle = -2 * 0.3 + 2;
  EXPECT_NEAR(poses[3].rotation(1, 0), std::sin(angle), 1e-15);
  const auto jacobian = robot.point_jacobian(poses, 3, poses[3].apply(Vec3(1, 0, 0)));
  // d/dq of (cos c, sin c, 0) at the point (1, 0, 0) of link c: dc/dq = -2.
  EXPECT_NEAR(jacobian(0, 0), 2 * std::sin(angle), 1e-14);
  EXPECT_NEAR(jacobian(1, 0), -2 * std::cos(angle), 1e-14);

  d.joints[0].mimic = "jc";  // now a cycle
  EXPECT_THROW((Robot(d)), proxima::InvalidInput);
}

}  // namespace
