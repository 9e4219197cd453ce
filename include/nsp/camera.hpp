// nsp/camera.hpp: the camera model light tracing needs (BdptEstimator's t = 1 strategy, THEORY
// 5.5): where a point appears on the image, and the density with which the camera's rays take a
// direction. A host with its own camera models the Camera concept; PinholeCamera is nsp's.
#pragma once

#include <cmath>
#include <concepts>

#include "core/error.hpp"
#include "core/math.hpp"

namespace nsp {

/// A camera for light tracing: `ray(u, v)` for image coordinates (u, v) in [0, 1)^2 (v = 0 at the
/// bottom); `position()`; `raster(w, u, v)`: the image coordinates of the ray leaving along unit
/// direction w, false if w misses the image; `pdf_dir(w)`: the solid-angle density of w among the
/// camera's rays when (u, v) is uniform over the image (0 where it misses). A light-tracing splat
/// of a path reaching the camera along -w is then beta f T pdf_dir(w) / d^2 (the camera's
/// importance times its cosine), added to the pixel at (u, v) and divided, as every sample of that
/// pixel, by the pixel's sample count.
template <class Cam>
concept Camera = requires(const Cam& c, float u, const Vec3& w, float& out) {
    { c.ray(u, u) } -> std::same_as<Ray>;
    { c.position() } -> std::convertible_to<Vec3>;
    { c.raster(w, out, out) } -> std::same_as<bool>;
    { c.pdf_dir(w) } -> std::same_as<float>;
};

/// A pinhole camera at `eye` looking at `target`, `up` roughly up, vertical field of view
/// `vfov_degrees`, width / height `aspect`: an image plane at distance 1 of size 2 tan_x x 2 tan_y.
/// In a right-handed world: u = 0 is the image's left column and v = 0 its bottom row as a viewer
/// at `eye` sees them (looking along +z with +y up, +x is on the left), as Mitsuba's and OpenGL's;
/// a host writes the sample at (u, v) to column u x width, row (1 - v) x height from the top.
class PinholeCamera {
public:
    /// Throws InvalidArgument on a non-finite eye or target, eye == target, `up` parallel to the
    /// view direction, a field of view outside (0, 180) degrees or an aspect that is not > 0.
    PinholeCamera(const Vec3& eye, const Vec3& target, const Vec3& up, float vfov_degrees, float aspect = 1.f)
        : eye_(eye) {
        if (!finite(eye) || !finite(target) || !finite(up))
            detail::fail("PinholeCamera: a non-finite eye, target or up vector is not allowed");
        const Vec3 d = target - eye;
        if (!(glm::dot(d, d) > 0.f)) detail::fail("PinholeCamera: eye and target coincide; they must differ");
        if (!(vfov_degrees > 0.f && vfov_degrees < 180.f))
            detail::fail("PinholeCamera vfov_degrees = ", vfov_degrees, " is not allowed: it must lie in (0, 180)");
        if (!(aspect > 0.f) || !std::isfinite(aspect))
            detail::fail("PinholeCamera aspect = ", aspect, " is not allowed: it must be finite and > 0");
        forward_ = glm::normalize(d);
        // Right-handed: the viewer's right is forward x up (looking along +z with +y up, -x).
        const Vec3 r = glm::cross(forward_, up);
        if (!(glm::dot(r, r) > 1e-12f)) detail::fail("PinholeCamera: up is parallel to the view direction");
        right_ = glm::normalize(r);
        up_ = glm::cross(right_, forward_);
        tan_y_ = std::tan(0.5f * vfov_degrees * kPi / 180.f);
        tan_x_ = tan_y_ * aspect;
        inv_area_ = 1.f / (4.f * tan_x_ * tan_y_);
    }

    Ray ray(float u, float v) const noexcept {
        return {eye_, glm::normalize(forward_ + (2.f * u - 1.f) * tan_x_ * right_ + (2.f * v - 1.f) * tan_y_ * up_)};
    }
    const Vec3& position() const noexcept { return eye_; }

    bool raster(const Vec3& w, float& u, float& v) const noexcept {
        const float c = glm::dot(w, forward_);
        if (!(c > 0.f)) return false;
        u = 0.5f * (glm::dot(w, right_) / (c * tan_x_) + 1.f);
        v = 0.5f * (glm::dot(w, up_) / (c * tan_y_) + 1.f);
        return u >= 0.f && u < 1.f && v >= 0.f && v < 1.f;
    }

    /// 1 / (A cos^3 theta): (u, v) uniform over the image plane of area A at distance 1.
    float pdf_dir(const Vec3& w) const noexcept {
        float u, v;
        if (!raster(w, u, v)) return 0.f;
        const float c = glm::dot(w, forward_);
        return inv_area_ / (c * c * c);
    }

private:
    Vec3 eye_, forward_{0.f, 0.f, 1.f}, right_{-1.f, 0.f, 0.f}, up_{0.f, 1.f, 0.f};
    float tan_x_ = 1.f, tan_y_ = 1.f, inv_area_ = 0.25f;
};

static_assert(Camera<PinholeCamera>);

}  // namespace nsp
