#pragma once
// Pinhole perspective and orthographic cameras from glTF camera nodes, optionally with a thin
// lens (depth of field), the image resolution they imply, and a default camera framing the
// scene's bounds when the file has none.
#include <optional>

#include "renderer/scene/scene.h"
#include "renderer/scene/scene_desc.h"

namespace chorus::render {

struct Resolution {
  int width = 0, height = 0;
};

inline constexpr int kDefaultImageHeight = 512;

// The image size: the requested width/height when both are given; one of them plus the
// camera's aspect ratio (square without one); or 512 rows and the camera's aspect.
Resolution chooseResolution(const CameraDesc& camera, int requestedWidth, int requestedHeight);

// What glTF viewers do without a camera: yfov 45°, looking down −Z at the centre of the bounds
// from the +Z side, far enough that the bounding sphere fits the narrower field of view.
CameraDesc framingCamera(const Bounds3f& bounds, float aspect);

// The scene's camera `index` (or the framing camera when the scene has none and index is 0).
// Throws chorus::Error naming the scene when index does not exist.
CameraDesc selectCamera(const Scene& scene, int index, float aspect);

class Camera {
 public:
  // The image aspect (width / height) overrides the camera's own: perspective keeps yfov,
  // orthographic keeps ymag. Throws chorus::Error for a lens radius that is not finite and ≥ 0,
  // a lens without a finite focus distance > 0, or a lens on an orthographic camera.
  Camera(const CameraDesc& desc, Resolution resolution);

  // The ray through raster position pRaster (x right, y down, in pixels; pixel (i, j) covers
  // [i, i+1) × [j, j+1)). Directions are unit length. With a thin lens, uLens ∈ [0,1)² picks the
  // point on the lens disk (concentric mapping) and the ray passes through the point the pinhole
  // ray reaches on the plane in focus, so that plane stays sharp: a point at distance z along
  // the axis is spread over a disk of radius lensRadius·|1/focusDistance − 1/z| on the image
  // plane at distance 1. Perspective cameras only (the constructor refuses an orthographic one
  // with a lens). Without a lens uLens is ignored.
  Ray generateRay(Vec2f pRaster, Vec2f uLens = {}) const;
  // Whether rays need a lens sample (the sampler draws one only then, so that pinhole renders
  // keep their sample dimensions).
  bool thinLens() const { return desc_.lensRadius > 0; }

  const CameraDesc& desc() const { return desc_; }
  Resolution resolution() const { return resolution_; }

 private:
  CameraDesc desc_;
  Resolution resolution_;
  float halfWidth_ = 1, halfHeight_ = 1;  // tan(fov/2) (perspective) or magnitudes (ortho)
};

}  // namespace chorus::render
