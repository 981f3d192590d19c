#include "renderer/integrator/camera.h"

#include <cmath>
#include <string>

#include "common/error.h"
#include "renderer/sampling/warps.h"

namespace chorus::render {

Resolution chooseResolution(const CameraDesc& camera, int requestedWidth, int requestedHeight) {
  const float aspect = camera.aspectRatio > 0 ? camera.aspectRatio : 1.0f;
  Resolution r;
  if (requestedWidth > 0 && requestedHeight > 0) {
    r = {requestedWidth, requestedHeight};
  } else if (requestedWidth > 0) {
    r = {requestedWidth, int(std::lround(float(requestedWidth) / aspect))};
  } else if (requestedHeight > 0) {
    r = {int(std::lround(float(requestedHeight) * aspect)), requestedHeight};
  } else {
    r = {int(std::lround(float(kDefaultImageHeight) * aspect)), kDefaultImageHeight};
  }
  r.width = std::max(1, r.width);
  r.height = std::max(1, r.height);
  return r;
}

CameraDesc framingCamera(const Bounds3f& bounds, float aspect) {
  CameraDesc c;
  c.name = "default (framing the scene bounds)";
  c.projection = ProjectionType::Perspective;
  c.yfov = kPi / 4.0f;
  const float xfov = 2.0f * std::atan(std::tan(c.yfov / 2.0f) * aspect);
  const float narrowFov = std::min(c.yfov, xfov);
  const float radius = std::max(bounds.radius(), 1e-6f);
  const float distance = radius / std::sin(narrowFov / 2.0f);
  const Vec3f center = bounds.empty() ? Vec3f{} : bounds.center();
  c.position = center + Vec3f{0, 0, distance};
  c.forward = {0, 0, -1};
  c.up = {0, 1, 0};
  c.right = {1, 0, 0};
  return c;
}

CameraDesc selectCamera(const Scene& scene, int index, float aspect) {
  const std::vector<CameraDesc>& cameras = scene.data().cameras;
  if (cameras.empty() && index == 0) return framingCamera(scene.bounds(), aspect);
  if (index < 0 || size_t(index) >= cameras.size())
    throw fileError(scene.data().source, "has no camera " + std::to_string(index) + " (it has " +
                                             std::to_string(cameras.size()) + ")");
  return cameras[size_t(index)];
}

Camera::Camera(const CameraDesc& desc, Resolution resolution)
    : desc_(desc), resolution_(resolution) {
  const float aspect = float(resolution.width) / float(resolution.height);
  if (desc.projection == ProjectionType::Perspective) {
    halfHeight_ = std::tan(desc.yfov / 2.0f);
  } else {
    halfHeight_ = desc.ymag;
  }
  halfWidth_ = halfHeight_ * aspect;
  if (!(desc.lensRadius >= 0) || !std::isfinite(desc.lensRadius))
    throw Error("the lens radius must be a finite number >= 0");
  if (desc.lensRadius > 0) {
    if (desc.projection != ProjectionType::Perspective)
      throw Error("depth of field needs a perspective camera (camera '" + desc.name +
                  "' is orthographic)");
    if (!(desc.focusDistance > 0) || !std::isfinite(desc.focusDistance))
      throw Error("the focus distance must be a finite number > 0");
  }
}

Ray Camera::generateRay(Vec2f pRaster, Vec2f uLens) const {
  // Normalised device coordinates in [−1, 1], y up.
  const float ndcX = 2.0f * pRaster.x / float(resolution_.width) - 1.0f;
  const float ndcY = 1.0f - 2.0f * pRaster.y / float(resolution_.height);
  Ray ray;
  if (desc_.projection == ProjectionType::Perspective) {
    // The pinhole direction with unit length along the axis: it reaches the plane in focus at
    // focusDistance times itself.
    const Vec3f axial =
        desc_.forward + desc_.right * (ndcX * halfWidth_) + desc_.up * (ndcY * halfHeight_);
    ray.origin = desc_.position;
    if (thinLens()) {
      const Vec2f disk = sampleConcentricDisk(uLens);
      const Vec3f onLens =
          desc_.right * (disk.x * desc_.lensRadius) + desc_.up * (disk.y * desc_.lensRadius);
      ray.origin = desc_.position + onLens;
      ray.direction = normalize(axial * desc_.focusDistance - onLens);
    } else {
      ray.direction = normalize(axial);
    }
  } else {
    ray.origin =
        desc_.position + desc_.right * (ndcX * halfWidth_) + desc_.up * (ndcY * halfHeight_);
    ray.direction = desc_.forward;
  }
  return ray;
}

}  // namespace chorus::render
