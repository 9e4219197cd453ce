// tests/support/control_scenes.hpp: BDPT's checks under a control (THEORY 5.10), grey and per
// channel: a SurfaceScene with its one medium replaced by another under a control, and the
// controls every check runs under.
#pragma once

#include <type_traits>

#include <nsp/nsp.hpp>

namespace nsp_test {

/// `base` with its one medium replaced by `m` under majorant (control) `maj`, HG phase `g`.
template <class Med, class Maj, class Base>
auto with_medium(const Base& base, const Med& m, const Maj& maj, float g) {
    using namespace nsp;
    using G = std::remove_cvref_t<decltype(base.geometry)>;
    using Mt = std::remove_cvref_t<decltype(base.materials)>;
    using L = std::remove_cvref_t<decltype(base.lights)>;
    using Out = SurfaceScene<G, Med, Maj, HenyeyGreensteinPhase, Mt, L>;
    return Out(base.geometry, {SceneMedium<Med, Maj, HenyeyGreensteinPhase>{m, maj, HenyeyGreensteinPhase(g)}},
               base.materials, base.lights, base.camera_medium);
}

/// Runs `check(scene, name)` on `base` with its medium `m` under a grid control of 4^3 (each cell's
/// density lower bound: a minorant), a tree control of 2^3 cells split into 2^3 wherever the bound
/// varies (two levels, the control read at a point from the finest cell), and a global control a
/// fifth of the way from the density's lower bound to its upper bound over the box: above the
/// density near its thin side (negative residuals, whose events and nulls are weighed by sign; per
/// channel the loop's control is the smallest channel's, so there it is that channel's residual).
template <class Med, class Base, class F>
void for_each_control(const Base& base, const Med& m, float g, F check) {
    using namespace nsp;
    check(with_medium(base, m, GridControl<Med>(m, 4), g), "grid control");
    check(with_medium(base, m, TreeControl<Med>(m, TreeLayout{m.bounds(), {2, 2, 2}, {2, 0, 0}, 0.f, 0.f}), g),
          "tree control");
    const float lo = m.density_lower_bound(m.bounds()), hi = m.density_bound(m.bounds());
    const float above = lo + 0.2f * (hi - lo);
    check(with_medium(base, m, GlobalControl<Med>(m, scale(m.extinction_per_density(), above)), g),
          "global control above the density");
}

}  // namespace nsp_test
