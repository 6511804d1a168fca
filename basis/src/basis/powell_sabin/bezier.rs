//! The Powell–Sabin Hermite interpolant in Bernstein–Bézier form
//! (`ps-splines.md` §4; paper eqs. (37)–(38)).
//!
//! Given values `f_k` and gradients `g_k` at the three vertices of a main triangle,
//! the unique C¹ piecewise quadratic on its PS refinement has the 19 Bézier ordinates
//!
//! | point | ordinate |
//! |---|---|
//! | `V_k` | `f_k` |
//! | `M_kl = (V_k + R_kl)/2` | `f_k + ½ g_k · (R_kl − V_k)` |
//! | `S_k = (V_k + Z)/2` | `f_k + ½ g_k · (Z − V_k)` |
//! | `R_kl = λ_k V_k + λ_l V_l` | `λ_k b(M_kl) + λ_l b(M_lk)` |
//! | `T_kl = (Z + R_kl)/2` | `λ_k b(S_k) + λ_l b(S_l)` |
//! | `Z = a V_1 + b V_2 + c V_3` | `a b(S_1) + b b(S_2) + c b(S_3)` |
//!
//! On each sub-triangle `(P_0, P_1, P_2)` the spline is
//! `Σ b_ijk 2!/(i! j! k!) τ_0^i τ_1^j τ_2^k`; ordinates are stored per sub-triangle in
//! the order [`BERNSTEIN_ORDER`].

use crate::mesh::Vec2;

/// Order of the six ordinates of a sub-triangle `(P_0, P_1, P_2)`:
/// `b_200, b_020, b_002, b_110, b_011, b_101` (corners, then edge midpoints
/// `P_0P_1`, `P_1P_2`, `P_0P_2`).
pub const BERNSTEIN_ORDER: [&str; 6] = ["b200", "b020", "b002", "b110", "b011", "b101"];

/// Geometry of one main triangle's PS refinement needed for the ordinates.
#[derive(Debug, Clone, Copy)]
pub struct MainTriangle {
    /// Vertices `V_0, V_1, V_2` (counter-clockwise).
    pub v: [Vec2; 3],
    /// Split point `Z`.
    pub z: Vec2,
    /// Barycentric coordinates `(a, b, c)` of `Z`.
    pub z_bary: [f64; 3],
    /// Edge point of local edge `m` (joining `V_m`, `V_{m+1}`).
    pub r: [Vec2; 3],
    /// `λ_m`: weight of `V_m` in `R_m` (the weight of `V_{m+1}` is `1 − λ_m`).
    pub r_lambda: [f64; 3],
}

/// The six sub-triangles' ordinates (in [`BERNSTEIN_ORDER`]) of the PS Hermite
/// interpolant with vertex values `f` and gradients `g`. Sub-triangle numbering as in
/// [`crate::refinement`]: `2m = (V_m, R_m, Z)`, `2m + 1 = (R_m, V_{m+1}, Z)`.
pub fn hermite_ordinates(tri: &MainTriangle, f: [f64; 3], g: [Vec2; 3]) -> [[f64; 6]; 6] {
    let v = &tri.v;
    // S_k and M on both ends of every edge.
    let s: [f64; 3] = std::array::from_fn(|k| f[k] + 0.5 * g[k].dot(&(tri.z - v[k])));
    // m_near[m] = b(M) at V_m on edge m; m_far[m] = b(M) at V_{m+1} on edge m.
    let m_near: [f64; 3] = std::array::from_fn(|m| f[m] + 0.5 * g[m].dot(&(tri.r[m] - v[m])));
    let m_far: [f64; 3] = std::array::from_fn(|m| {
        let n = (m + 1) % 3;
        f[n] + 0.5 * g[n].dot(&(tri.r[m] - v[n]))
    });
    let r: [f64; 3] =
        std::array::from_fn(|m| tri.r_lambda[m] * m_near[m] + (1.0 - tri.r_lambda[m]) * m_far[m]);
    let t: [f64; 3] = std::array::from_fn(|m| {
        let n = (m + 1) % 3;
        tri.r_lambda[m] * s[m] + (1.0 - tri.r_lambda[m]) * s[n]
    });
    let z = tri.z_bary[0] * s[0] + tri.z_bary[1] * s[1] + tri.z_bary[2] * s[2];
    let mut out = [[0.0; 6]; 6];
    for m in 0..3 {
        let n = (m + 1) % 3;
        // (V_m, R_m, Z): edges V_m–R_m (M near V_m), R_m–Z (T_m), V_m–Z (S_m).
        out[2 * m] = [f[m], r[m], z, m_near[m], t[m], s[m]];
        // (R_m, V_n, Z): edges R_m–V_n (M near V_n), V_n–Z (S_n), R_m–Z (T_m).
        out[2 * m + 1] = [r[m], f[n], z, m_far[m], s[n], t[m]];
    }
    out
}

/// The six quadratic Bernstein polynomials at barycentric `tau`, in [`BERNSTEIN_ORDER`],
/// and their derivatives with respect to `tau_0, tau_1, tau_2`.
#[inline]
pub fn bernstein<T: crate::Real>(tau: [T; 3]) -> ([T; 6], [[T; 3]; 6]) {
    let two = T::one() + T::one();
    let z = T::zero();
    let [t0, t1, t2] = tau;
    (
        [
            t0 * t0,
            t1 * t1,
            t2 * t2,
            two * t0 * t1,
            two * t1 * t2,
            two * t0 * t2,
        ],
        [
            [two * t0, z, z],
            [z, two * t1, z],
            [z, z, two * t2],
            [two * t1, two * t0, z],
            [z, two * t2, two * t1],
            [two * t2, z, two * t0],
        ],
    )
}
