#include "triangulation/solid_angle.hpp"

#include <gtest/gtest.h>

#include <cmath>

using pfv::Vec3;

TEST(SolidAngle, OctantIsAnEighthOfTheSphere) {
  EXPECT_NEAR(pfv::solid_angle(Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()), 4 * M_PI / 8, 1e-14);
}

TEST(SolidAngle, RegularTetrahedronVertex) {
  const Vec3 a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  const double expected = 3 * std::acos(1.0 / 3.0) - M_PI;  // spherical excess
  EXPECT_NEAR(pfv::solid_angle((b - a).normalized(), (c - a).normalized(), (d - a).normalized()), expected, 1e-14);
}

TEST(SolidAngle, ObtuseConeBeyondAHemisphereFace) {
  // Three directions nearly in a plane but spanning more than a half-space's cone: the
  // denominator is negative and atan2 must return an angle above pi.
  const Vec3 e1(1, 0, -0.01), e2(-0.5, std::sqrt(3.0) / 2, -0.01), e3(-0.5, -std::sqrt(3.0) / 2, -0.01);
  const double om = pfv::solid_angle(e1.normalized(), e2.normalized(), e3.normalized());
  EXPECT_GT(om, M_PI);
  EXPECT_LT(om, 2 * M_PI);
}

TEST(PlanarAngle, RightAngle) { EXPECT_NEAR(pfv::planar_angle(Vec3::UnitX(), Vec3::UnitY()), M_PI / 2, 1e-15); }
