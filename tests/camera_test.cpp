// Camera rays against the projection's definition, resolution rules and the framing camera.
#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "renderer/integrator/camera.h"
#include "renderer/sampling/warps.h"

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

// A thin lens: every ray of a pixel passes through the pinhole ray's point on the plane in focus,
// and a point at another depth z is seen displaced by −L·(1/f − 1/z) on the image plane at
// distance 1 (L the lens point in the right/up frame): the circle of confusion of radius
// R·|1/f − 1/z|. Derived from similar triangles, checked against rays traced to plane z.
TEST(Camera, ThinLensFocusesItsPlaneAndSpreadsOthersByTheCircleOfConfusion) {
  CameraDesc desc = lookingDownZ();
  desc.yfov = 1.0f;
  const Camera pinhole(desc, {64, 48});
  desc.lensRadius = 0.3f;
  desc.focusDistance = 2.5f;
  const Camera lens(desc, {64, 48});
  EXPECT_TRUE(lens.thinLens());
  EXPECT_FALSE(pinhole.thinLens());
  const auto atDepth = [&](const Ray& r, float z) {  // the ray's point at distance z along −z
    const float t = z / -r.direction.z;
    return r.origin + r.direction * t;
  };
  const auto imagePlane = [&](Vec3f p) {  // pinhole projection, image plane at distance 1
    const Vec3f d = p - desc.position;
    return Vec2f{d.x / -d.z, d.y / -d.z};
  };
  float largest = 0;
  for (const Vec2f pixel : {Vec2f{32, 24}, Vec2f{3.5f, 40.25f}, Vec2f{60, 2}}) {
    const Ray centre = pinhole.generateRay(pixel);
    const Vec3f focused = atDepth(centre, 2.5f);
    const Vec2f s = imagePlane(atDepth(centre, 7.0f));
    for (int i = 0; i < 16; ++i)
      for (int j = 0; j < 16; ++j) {
        const Vec2f u{(float(i) + 0.5f) / 16, (float(j) + 0.5f) / 16};
        const Ray r = lens.generateRay(pixel, u);
        EXPECT_NEAR(length(r.direction), 1.0f, 1e-5f);
        const Vec3f f = atDepth(r, 2.5f);
        EXPECT_NEAR(f.x, focused.x, 1e-4f);
        EXPECT_NEAR(f.y, focused.y, 1e-4f);
        // At z = 7 the image point moves by −L·(1/2.5 − 1/7).
        const Vec2f disk = sampleConcentricDisk(u);
        const Vec2f seen = imagePlane(atDepth(r, 7.0f));
        const float k = 0.3f * (1 / 2.5f - 1 / 7.0f);
        EXPECT_NEAR(seen.x - s.x, -disk.x * k, 1e-4f);
        EXPECT_NEAR(seen.y - s.y, -disk.y * k, 1e-4f);
        largest = std::max(largest, std::hypot(seen.x - s.x, seen.y - s.y));
      }
  }
  // The outermost samples reach the disk's rim (16 × 16 samples: within 10 %).
  EXPECT_GT(largest, 0.9f * 0.3f * (1 / 2.5f - 1 / 7.0f));
  EXPECT_LE(largest, 1.0001f * 0.3f * (1 / 2.5f - 1 / 7.0f));
}

TEST(Camera, ThinLensRefusesWhatItCannotFocus) {
  CameraDesc desc = lookingDownZ();
  desc.lensRadius = 0.1f;  // no focus distance
  EXPECT_THROW(Camera(desc, {8, 8}), Error);
  desc.focusDistance = 1.0f;
  EXPECT_NO_THROW(Camera(desc, {8, 8}));
  for (float bad : {-0.1f, std::nanf(""), INFINITY}) {
    CameraDesc d = desc;
    d.lensRadius = bad;
    EXPECT_THROW(Camera(d, {8, 8}), Error) << bad;
  }
  desc.projection = ProjectionType::Orthographic;
  EXPECT_THROW(Camera(desc, {8, 8}), Error);
}

}  // namespace
}  // namespace chorus::render
