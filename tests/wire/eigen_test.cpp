// Pins the Eigen conventions: column-major poses, translation at 12..14, no copies.
#include "rsg/wire/eigen.hpp"

#include <gtest/gtest.h>

#include <array>

namespace rsg::wire {
namespace {

// The shapes of a RobotState sample's members (O_T_EE, q, O_F_ext_hat_K, I_ee, F_x_Cee).
struct State {
  std::array<double, 16> O_T_EE{};
  std::array<double, 7> q{}, dq{};
  std::array<double, 6> O_F_ext_hat_K{};
  std::array<double, 9> I_ee{};
  std::array<double, 3> F_x_Cee{};
};

TEST(Eigen, PoseIsColumnMajorWithTranslationAt12To14) {
  State sample;
  auto& m = sample.O_T_EE;
  for (std::size_t i = 0; i < 16; ++i) m[i] = static_cast<double>(i);
  const auto pose = eigen::pose(sample.O_T_EE);
  EXPECT_EQ(pose(0, 3), 12.0);
  EXPECT_EQ(pose(1, 3), 13.0);
  EXPECT_EQ(pose(2, 3), 14.0);
  EXPECT_EQ(pose(1, 0), 1.0);  // element 1 is row 1 of column 0
  EXPECT_EQ(pose.data(), m.data());
}

TEST(Eigen, IsometryCarriesRotationAndTranslation) {
  State sample;
  Eigen::Isometry3d expected =
      Eigen::Translation3d(0.3, -0.1, 0.5) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  eigen::pose(sample.O_T_EE) = expected.matrix();
  EXPECT_EQ(sample.O_T_EE[12], 0.3);
  EXPECT_EQ(sample.O_T_EE[13], -0.1);
  EXPECT_EQ(sample.O_T_EE[14], 0.5);
  EXPECT_TRUE(eigen::isometry(sample.O_T_EE).isApprox(expected));
}

TEST(Eigen, VectorsAndInertiasMapInPlace) {
  State sample;
  eigen::joints(sample.q) = eigen::Vector7d::LinSpaced(7, 1, 7);
  EXPECT_EQ(sample.q[6], 7.0);
  eigen::vector6(sample.O_F_ext_hat_K)(3) = 2.5;  // torque x
  EXPECT_EQ(sample.O_F_ext_hat_K[3], 2.5);
  eigen::inertia(sample.I_ee)(0, 2) = 4.0;  // column-major: element 6
  EXPECT_EQ(sample.I_ee[6], 4.0);
  eigen::vector3(sample.F_x_Cee)(2) = 0.1;
  EXPECT_EQ(sample.F_x_Cee[2], 0.1);
  EXPECT_EQ(eigen::joints(sample.dq).data(), sample.dq.data());
}

}  // namespace
}  // namespace rsg::wire
