#pragma once
// Affine transforms in double precision (node hierarchies compose many of them; the result is
// applied once per vertex and rounded to float). Named by the spaces they map between:
// pWorld = worldFromObject.point(pObject).
#include <array>
#include <cmath>

#include "renderer/math/vec.h"

namespace chorus::render {

class Transform {
 public:
  // Identity.
  Transform() : m_{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0} {}

  // From a glTF column-major 4×4 matrix (the last row is assumed to be 0 0 0 1).
  static Transform fromColumnMajor(const double* m16) {
    Transform t;
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col) t.at(row, col) = m16[col * 4 + row];
    return t;
  }
  // glTF TRS: T · R · S, rotation a unit quaternion (x, y, z, w).
  static Transform fromTrs(const std::array<double, 3>& translation,
                           const std::array<double, 4>& rotation,
                           const std::array<double, 3>& scale) {
    double x = rotation[0], y = rotation[1], z = rotation[2], w = rotation[3];
    const double norm = std::sqrt(x * x + y * y + z * z + w * w);
    if (norm > 0) x /= norm, y /= norm, z /= norm, w /= norm;
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    Transform t;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) t.at(row, col) = r[row][col] * scale[size_t(col)];
      t.at(row, 3) = translation[size_t(row)];
    }
    return t;
  }

  // (this ∘ other): applies `other` first.
  Transform operator*(const Transform& other) const {
    Transform t;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 4; ++col) {
        double v = col == 3 ? at(row, 3) : 0.0;
        for (int k = 0; k < 3; ++k) v += at(row, k) * other.at(k, col);
        t.at(row, col) = v;
      }
    }
    return t;
  }

  Vec3f point(Vec3f p) const {
    return {float(at(0, 0) * p.x + at(0, 1) * p.y + at(0, 2) * p.z + at(0, 3)),
            float(at(1, 0) * p.x + at(1, 1) * p.y + at(1, 2) * p.z + at(1, 3)),
            float(at(2, 0) * p.x + at(2, 1) * p.y + at(2, 2) * p.z + at(2, 3))};
  }
  Vec3f vector(Vec3f v) const {
    return {float(at(0, 0) * v.x + at(0, 1) * v.y + at(0, 2) * v.z),
            float(at(1, 0) * v.x + at(1, 1) * v.y + at(1, 2) * v.z),
            float(at(2, 0) * v.x + at(2, 1) * v.y + at(2, 2) * v.z)};
  }
  // Normals transform by the inverse transpose; the cofactor matrix is that up to the
  // determinant's factor, which only scales (and for det < 0 flips) them, so callers normalise
  // and orient normals themselves.
  Vec3f normal(Vec3f n) const {
    const double c00 = at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1);
    const double c01 = at(1, 2) * at(2, 0) - at(1, 0) * at(2, 2);
    const double c02 = at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0);
    const double c10 = at(0, 2) * at(2, 1) - at(0, 1) * at(2, 2);
    const double c11 = at(0, 0) * at(2, 2) - at(0, 2) * at(2, 0);
    const double c12 = at(0, 1) * at(2, 0) - at(0, 0) * at(2, 1);
    const double c20 = at(0, 1) * at(1, 2) - at(0, 2) * at(1, 1);
    const double c21 = at(0, 2) * at(1, 0) - at(0, 0) * at(1, 2);
    const double c22 = at(0, 0) * at(1, 1) - at(0, 1) * at(1, 0);
    const double sign = determinant() < 0 ? -1.0 : 1.0;
    return {float(sign * (c00 * n.x + c01 * n.y + c02 * n.z)),
            float(sign * (c10 * n.x + c11 * n.y + c12 * n.z)),
            float(sign * (c20 * n.x + c21 * n.y + c22 * n.z))};
  }
  double determinant() const {
    return at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) -
           at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0)) +
           at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
  }

  double at(int row, int col) const { return m_[size_t(row * 4 + col)]; }
  double& at(int row, int col) { return m_[size_t(row * 4 + col)]; }

 private:
  std::array<double, 12> m_;  // rows 0..2 of a 4×4 affine matrix, row-major
};

}  // namespace chorus::render
