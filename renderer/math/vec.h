#pragma once
// Small value types for the renderer: Vec2f, Vec3f (points, directions, normals), Rgb
// (radiometric quantities), and Frame (an orthonormal basis for local shading coordinates).
#include <algorithm>
#include <cmath>

namespace chorus::render {

struct Vec2f {
  float x = 0, y = 0;
  constexpr Vec2f() = default;
  constexpr Vec2f(float x_, float y_) : x(x_), y(y_) {}
  constexpr Vec2f operator+(Vec2f o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2f operator-(Vec2f o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2f operator*(float s) const { return {x * s, y * s}; }
  constexpr float operator[](int i) const { return i == 0 ? x : y; }
};

struct Vec3f {
  float x = 0, y = 0, z = 0;
  constexpr Vec3f() = default;
  constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr Vec3f operator+(Vec3f o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3f operator-(Vec3f o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3f operator-() const { return {-x, -y, -z}; }
  constexpr Vec3f operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3f operator/(float s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3f& operator+=(Vec3f o) {
    x += o.x, y += o.y, z += o.z;
    return *this;
  }
  constexpr Vec3f& operator-=(Vec3f o) {
    x -= o.x, y -= o.y, z -= o.z;
    return *this;
  }
  constexpr Vec3f& operator*=(float s) {
    x *= s, y *= s, z *= s;
    return *this;
  }
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};
constexpr Vec3f operator*(float s, Vec3f v) {
  return v * s;
}
constexpr float dot(Vec3f a, Vec3f b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3f cross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3f v) {
  return std::sqrt(dot(v, v));
}
constexpr float lengthSquared(Vec3f v) {
  return dot(v, v);
}
inline Vec3f normalize(Vec3f v) {
  return v / length(v);
}
inline Vec3f abs(Vec3f v) {
  return {std::abs(v.x), std::abs(v.y), std::abs(v.z)};
}
inline Vec3f min(Vec3f a, Vec3f b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
inline Vec3f max(Vec3f a, Vec3f b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
constexpr float maxComponent(Vec3f v) {
  return std::max(v.x, std::max(v.y, v.z));
}
inline bool isFinite(Vec3f v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
// v flipped, when needed, to lie in the hemisphere of `reference`.
constexpr Vec3f faceForward(Vec3f v, Vec3f reference) {
  return dot(v, reference) < 0 ? -v : v;
}

// Linear RGB radiometric value (radiance, throughput, reflectance).
struct Rgb {
  float r = 0, g = 0, b = 0;
  constexpr Rgb() = default;
  constexpr explicit Rgb(float v) : r(v), g(v), b(v) {}
  constexpr Rgb(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
  constexpr Rgb operator+(Rgb o) const { return {r + o.r, g + o.g, b + o.b}; }
  constexpr Rgb operator-(Rgb o) const { return {r - o.r, g - o.g, b - o.b}; }
  constexpr Rgb operator*(Rgb o) const { return {r * o.r, g * o.g, b * o.b}; }
  constexpr Rgb operator/(Rgb o) const { return {r / o.r, g / o.g, b / o.b}; }
  constexpr Rgb operator*(float s) const { return {r * s, g * s, b * s}; }
  constexpr Rgb operator/(float s) const { return {r / s, g / s, b / s}; }
  constexpr Rgb& operator+=(Rgb o) {
    r += o.r, g += o.g, b += o.b;
    return *this;
  }
  constexpr Rgb& operator*=(Rgb o) {
    r *= o.r, g *= o.g, b *= o.b;
    return *this;
  }
  constexpr Rgb& operator*=(float s) {
    r *= s, g *= s, b *= s;
    return *this;
  }
  constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr bool isBlack() const { return r == 0 && g == 0 && b == 0; }
  constexpr float maxComponent() const { return std::max(r, std::max(g, b)); }
  constexpr float average() const { return (r + g + b) / 3.0f; }
  // Rec. 709 / sRGB luminance.
  constexpr float luminance() const { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
  bool isFinite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
};
constexpr Rgb operator*(float s, Rgb c) {
  return c * s;
}
inline Rgb exp(Rgb c) {
  return {std::exp(c.r), std::exp(c.g), std::exp(c.b)};
}

// Orthonormal basis (x, y, z); local shading coordinates have z = the shading normal.
struct Frame {
  Vec3f x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};

  // A frame around unit vector n (Duff et al. 2017, "Building an orthonormal basis, revisited").
  static Frame fromZ(Vec3f n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    Frame f;
    f.x = {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    f.y = {b, sign + n.y * n.y * a, -n.y};
    f.z = n;
    return f;
  }
  // A frame with z = n and x along the projection of tangent t (Gram–Schmidt); falls back to
  // fromZ when t is (nearly) parallel to n.
  static Frame fromZX(Vec3f n, Vec3f t) {
    const Vec3f tp = t - n * dot(n, t);
    const float len = length(tp);
    if (!(len > 1e-6f)) return fromZ(n);
    Frame f;
    f.z = n;
    f.x = tp / len;
    f.y = cross(n, f.x);
    return f;
  }
  Vec3f toLocal(Vec3f v) const { return {dot(v, x), dot(v, y), dot(v, z)}; }
  Vec3f fromLocal(Vec3f v) const { return x * v.x + y * v.y + z * v.z; }
};

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;

}  // namespace chorus::render
