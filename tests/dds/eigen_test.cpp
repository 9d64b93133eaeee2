// Pins the Eigen conventions: column-major poses, translation at 12..14, no copies.
#include "rsg/dds/eigen.hpp"

#include <gtest/gtest.h>

#include "rsg/dds/robot_state.hpp"

namespace rsg {
namespace {

TEST(Eigen, PoseIsColumnMajorWithTranslationAt12To14) {
  RobotState sample;
  auto& m = sample.O_T_EE();
  for (std::size_t i = 0; i < 16; ++i) m[i] = static_cast<double>(i);
  const auto pose = dds::eigen::pose(sample.O_T_EE());
  EXPECT_EQ(pose(0, 3), 12.0);
  EXPECT_EQ(pose(1, 3), 13.0);
  EXPECT_EQ(pose(2, 3), 14.0);
  EXPECT_EQ(pose(1, 0), 1.0);  // element 1 is row 1 of column 0
  EXPECT_EQ(pose.data(), m.data());
}

TEST(Eigen, IsometryCarriesRotationAndTranslation) {
  RobotState sample;
  Eigen::Isometry3d expected =
      Eigen::Translation3d(0.3, -0.1, 0.5) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  dds::eigen::pose(sample.O_T_EE()) = expected.matrix();
  EXPECT_EQ(sample.O_T_EE()[12], 0.3);
  EXPECT_EQ(sample.O_T_EE()[13], -0.1);
  EXPECT_EQ(sample.O_T_EE()[14], 0.5);
  EXPECT_TRUE(dds::eigen::isometry(sample.O_T_EE()).isApprox(expected));
}

TEST(Eigen, VectorsAndInertiasMapInPlace) {
  RobotState sample;
  dds::eigen::joints(sample.q()) = dds::eigen::Vector7d::LinSpaced(7, 1, 7);
  EXPECT_EQ(sample.q()[6], 7.0);
  dds::eigen::vector6(sample.O_F_ext_hat_K())(3) = 2.5;  // torque x
  EXPECT_EQ(sample.O_F_ext_hat_K()[3], 2.5);
  dds::eigen::inertia(sample.I_ee())(0, 2) = 4.0;  // column-major: element 6
  EXPECT_EQ(sample.I_ee()[6], 4.0);
  dds::eigen::vector3(sample.F_x_Cee())(2) = 0.1;
  EXPECT_EQ(sample.F_x_Cee()[2], 0.1);
  EXPECT_EQ(dds::eigen::joints(sample.dq()).data(), sample.dq().data());
}

}  // namespace
}  // namespace rsg
