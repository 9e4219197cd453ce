// tests/support/majorants.hpp: the majorant axis of the generic suites. Each kind is a factory
// for a medium M: the tight global majorant, grid majorants at a resolution that does not align
// with any test grid's voxels, and non-bounding (scale 0.5) grid majorants under bound::Signed
// (unbiased) and bound::Clamp (exact for the clamped medium).
#pragma once

#include <algorithm>
#include <array>
#include <string>
#include <tuple>
#include <type_traits>

#include "common.hpp"

namespace nsp_test {

/// The grid resolution the suites use: coarse, non-cubic and not aligned with the 5 x 4 x 6
/// voxels of MediumKind<DenseGridMedium>, so cells straddle voxels.
inline constexpr std::array<int, 3> kTestGridRes{3, 4, 2};

struct GlobalKind {
    static constexpr const char* name = "global";
    template <class M> using type = GlobalMajorant<M>;
    template <class M> static type<M> make(const M& m) { return type<M>(m); }
};
struct ChannelKind {
    static constexpr const char* name = "per-channel";
    template <class M> using type = ChannelMajorant<M>;
    template <class M> static type<M> make(const M& m) { return type<M>(m); }
};
struct GridKind {
    static constexpr const char* name = "grid";
    template <class M> using type = GridMajorant<M>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, kTestGridRes); }
};
struct ChannelGridKind {
    static constexpr const char* name = "channel-grid";
    template <class M> using type = ChannelGridMajorant<M>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, kTestGridRes); }
};
/// The tree majorants over a layout that does not align with the test grids' voxels either:
/// 2 x 2 x 1 coarse cells, each split into 2^3 wherever the bound varies (costs 0: the test
/// grids are too small for the cost model to split them).
inline constexpr std::array<int, 3> kTestTreeCoarse{2, 2, 1};
struct TreeKind {
    static constexpr const char* name = "tree";
    template <class M> using type = TreeMajorant<M>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, TreeLayout{m.bounds(), kTestTreeCoarse, {2, 0, 0}, 0.f, 0.f}); }
};
struct ChannelTreeKind {
    static constexpr const char* name = "channel-tree";
    template <class M> using type = ChannelTreeMajorant<M>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, TreeLayout{m.bounds(), kTestTreeCoarse, {2, 0, 0}, 0.f, 0.f}); }
};
/// Half the global bound, signed weights (policy a): unbiased; applies to every medium.
struct SignedGlobalKind {
    static constexpr const char* name = "global-signed-0.5";
    template <class M> using type = GlobalMajorant<M, bound::Signed>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, 0.5f * m.max_extinction()); }
};
/// Half the grid bound, signed weights (policy a): unbiased.
struct SignedGridKind {
    static constexpr const char* name = "grid-signed-0.5";
    template <class M> using type = GridMajorant<M, bound::Signed>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, kTestGridRes, 0.5f); }
};
struct SignedChannelGridKind {
    static constexpr const char* name = "channel-grid-signed-0.5";
    template <class M> using type = ChannelGridMajorant<M, bound::Signed>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, kTestGridRes, 0.5f); }
};
/// Half the grid bound, density clamped to it (policy b): biased towards the clamped medium.
struct ClampGridKind {
    static constexpr const char* name = "grid-clamp-0.5";
    template <class M> using type = GridMajorant<M, bound::Clamp>;
    template <class M> static type<M> make(const M& m) { return type<M>(m, kTestGridRes, 0.5f); }
};

/// A medium made of two grids, as a host's may be: mu_t,c(p) = a_c r(x) + b_c r(y) with the
/// ramps r(s) = (s + 1) / 2 over [-1, 1]^3 (scattering half of it); no single density, so it
/// bounds its extinction per channel over a region (ExtinctionBoundedMedium): a_c r(hi.x) +
/// b_c r(hi.y), both ramps rising, hi clamped to the box.
template <SpectralMode S>
struct TwoGridMedium {
    using Spectral = S;
    using Spectrum = typename S::Spectrum;
    Spectrum a, b;

    static float ramp(float s) { return 0.5f * (std::clamp(s, -1.f, 1.f) + 1.f); }
    Box bounds() const { return Box{Vec3(-1.f), Vec3(1.f)}; }
    Coefficients<S> coefficients(const Vec3& p, const typename S::Wavelengths& = {}) const {
        if (!bounds().contains(p)) return {Spectrum::Zero(), Spectrum::Zero()};
        const Spectrum t = a * ramp(p.x) + b * ramp(p.y);
        return {Spectrum(0.5f * t), Spectrum(0.5f * t)};
    }
    Spectrum extinction_bound_over(const Box& r) const { return a * ramp(r.hi.x) + b * ramp(r.hi.y); }
    Spectrum extinction_bound_coefficient() const { return a + b; }
    Spectrum extinction_bound(const typename S::Wavelengths& = {}) const { return a + b; }
    float max_extinction() const { return (a + b).maxCoeff(); }
    /// Every channel's optical depth along r over [0, tmax]: the ramps are linear along the ray.
    Spectrum optical_depth(const Ray& r, float tmax) const {
        const Interval in = bounds().clip(r, 0.f, tmax);
        if (!(in.t1 > in.t0)) return Spectrum::Zero();
        const Vec3 m = r.at(0.5f * (in.t0 + in.t1));
        return Spectrum((a * ramp(m.x) + b * ramp(m.y)) * (in.t1 - in.t0));
    }
};
/// True when majorant kind K can be built for medium M (grid kinds need a RegionBoundedMedium).
template <class K, class M>
inline constexpr bool kind_applies_v = requires(const M& m) { K::make(m); };

namespace detail {
template <class M, class K, class F>
void call_if_applies(F& f, K k) {
    if constexpr (kind_applies_v<K, M>) f(k);
}
}  // namespace detail

/// Calls f(K{}) for every kind K in the tuple type Kinds that applies to medium M.
template <class Kinds, class M, class F>
void for_each_kind(F&& f) {
    std::apply([&](auto... k) { (detail::call_if_applies<M>(f, k), ...); }, Kinds{});
}

/// The grey majorant kinds the pdf suites run over besides the global majorant: every model and
/// every bound policy whose pdfs are evaluated independently (Reject only discards).
using PdfGreyKinds = std::tuple<SignedGlobalKind, GridKind, SignedGridKind, ClampGridKind, TreeKind>;

/// The grey majorant kinds whose estimates are unbiased for the medium itself.
using UnbiasedGreyKinds = std::tuple<GlobalKind, GridKind, SignedGridKind, TreeKind>;

/// True when channel c's majorant is positive somewhere on [0, tmax] of `ray`.
template <Medium M, class Maj>
bool channel_has_majorant(const Maj& maj, const Ray& ray, float tmax, const typename M::Spectral::Wavelengths& l,
                          int c) {
    auto it = maj.iterate(ray, 0.f, tmax, l);
    while (auto seg = it.next())
        if (channel_of(seg->sigma_maj, c) > 0.f) return true;
    return false;
}

}  // namespace nsp_test
