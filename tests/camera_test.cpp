// Camera rays against the projection's definition, resolution rules and the framing camera.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/integrator/camera.h"

namespace chorus::render {
namespace {

CameraDesc lookingDownZ() {
  CameraDesc c;
  c.position = {1, 2, 3};
  return c;
}

float angleBetween(Vec3f a, Vec3f b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0f, 1.0f));
}

TEST(Camera, PerspectiveEdgesSpanTheFieldOfView) {
  CameraDesc desc = lookingDownZ();
  desc.yfov = 0.8f;
  const Camera camera(desc, {200, 100});
  const Ray centre = camera.generateRay({100, 50});
  EXPECT_NEAR(centre.direction.z, -1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(centre.origin.y, 2.0f);
  // Top edge: half the vertical field of view above the axis.
  const Ray top = camera.generateRay({100, 0});
  EXPECT_NEAR(angleBetween(top.direction, {0, 0, -1}), 0.4f, 1e-5f);
  EXPECT_GT(top.direction.y, 0.0f);
  // Right edge: the horizontal half-angle follows the image aspect (2:1).
  const Ray right = camera.generateRay({200, 50});
  EXPECT_NEAR(std::tan(angleBetween(right.direction, {0, 0, -1})), 2.0f * std::tan(0.4f), 1e-5f);
  EXPECT_GT(right.direction.x, 0.0f);
  EXPECT_NEAR(length(right.direction), 1.0f, 1e-6f);
}

TEST(Camera, OrthographicRaysAreParallelAndSpanYmag) {
  CameraDesc desc = lookingDownZ();
  desc.projection = ProjectionType::Orthographic;
  desc.ymag = 3.0f;
  const Camera camera(desc, {50, 100});
  const Ray topLeft = camera.generateRay({0, 0});
  const Ray bottomRight = camera.generateRay({50, 100});
  for (const Ray& r : {topLeft, bottomRight}) {
    EXPECT_FLOAT_EQ(r.direction.z, -1.0f);
    EXPECT_FLOAT_EQ(r.direction.x, 0.0f);
  }
  EXPECT_FLOAT_EQ(topLeft.origin.y, 2.0f + 3.0f);
  EXPECT_FLOAT_EQ(bottomRight.origin.y, 2.0f - 3.0f);
  EXPECT_FLOAT_EQ(bottomRight.origin.x - topLeft.origin.x, 2.0f * 3.0f * 0.5f);
}

TEST(Camera, ResolutionFollowsRequestAndAspect) {
  CameraDesc wide;
  wide.aspectRatio = 2.0f;
  EXPECT_EQ(chooseResolution(wide, 0, 0).width, 1024);
  EXPECT_EQ(chooseResolution(wide, 0, 0).height, 512);
  EXPECT_EQ(chooseResolution(wide, 300, 0).height, 150);
  EXPECT_EQ(chooseResolution(wide, 0, 100).width, 200);
  EXPECT_EQ(chooseResolution(wide, 64, 48).width, 64);
  EXPECT_EQ(chooseResolution(CameraDesc{}, 0, 0).width, 512);
  EXPECT_EQ(chooseResolution(CameraDesc{}, 0, 0).height, 512);
}

TEST(Camera, FramingCameraSeesTheWholeBounds) {
  Bounds3f bounds;
  bounds.extend({-3, 10, 5});
  bounds.extend({7, 12, 9});
  for (float aspect : {0.5f, 1.0f, 2.0f}) {
    const CameraDesc c = framingCamera(bounds, aspect);
    EXPECT_FLOAT_EQ(c.forward.z, -1.0f);
    const float tanY = std::tan(c.yfov / 2), tanX = tanY * aspect;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3f p{corner & 1 ? bounds.max.x : bounds.min.x,
                    corner & 2 ? bounds.max.y : bounds.min.y,
                    corner & 4 ? bounds.max.z : bounds.min.z};
      const Vec3f d = p - c.position;
      const float depth = dot(d, c.forward);
      ASSERT_GT(depth, 0.0f);
      EXPECT_LE(std::abs(dot(d, c.right)) / depth, tanX * 1.0001f) << "aspect " << aspect;
      EXPECT_LE(std::abs(dot(d, c.up)) / depth, tanY * 1.0001f) << "aspect " << aspect;
    }
  }
}

}  // namespace
}  // namespace chorus::render
