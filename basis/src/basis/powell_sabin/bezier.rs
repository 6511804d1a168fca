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

/// The ordinates of a function of vertex `V_k` that can be non-zero, of the 19 of
/// its Hermite interpolant: the function's value and gradient vanish at the other
/// two vertices, so its ordinates at them, at their `M` and `S` points, and at the
/// `R` and `T` points of the edge between them are exactly zero (`+0.0`, 10 of
/// the 19). The nine kept: `[b(V_k), b(S_k), b(M_k), b(M'_k), b(R_k), b(R_{k−1}),
/// b(T_k), b(T_{k−1}), b(Z)]`, with `M_k` the `M` point of edge `k` (from `V_k`)
/// and `M'_k` that of edge `k − 1` (into `V_k`). A ninth of the storage of the
/// sub-triangles' 36 monomials per function, and [`expand`] gives back the
/// sub-triangles' ordinates bit for bit ([`compact`]).
pub type VertexOrdinates = [f64; 9];

/// Marks an ordinate that is exactly zero in [`PLACES`].
const ZERO: u8 = 9;

/// `PLACES[k][s][j]`: where ordinate `j` (in [`BERNSTEIN_ORDER`]) of sub-triangle
/// `s` of a function of vertex `k` is kept in its [`VertexOrdinates`], or `ZERO`;
/// the layout of [`hermite_ordinates`].
const PLACES: [[[u8; 6]; 6]; 3] = [places(0), places(1), places(2)];

const fn places(k: usize) -> [[u8; 6]; 6] {
    const fn pick(here: bool, place: u8) -> u8 {
        if here {
            place
        } else {
            ZERO
        }
    }
    let before = (k + 2) % 3;
    let mut out = [[ZERO; 6]; 6];
    let mut m = 0;
    while m < 3 {
        let n = (m + 1) % 3;
        let r = if m == k { 4 } else { pick(m == before, 5) };
        let t = if m == k { 6 } else { pick(m == before, 7) };
        // (V_m, R_m, Z): [f_m, r_m, z, m_near_m, t_m, s_m].
        out[2 * m] = [pick(m == k, 0), r, 8, pick(m == k, 2), t, pick(m == k, 1)];
        // (R_m, V_n, Z): [r_m, f_n, z, m_far_m, s_n, t_m].
        out[2 * m + 1] = [r, pick(n == k, 0), 8, pick(n == k, 3), pick(n == k, 1), t];
        m += 1;
    }
    out
}

/// The [`VertexOrdinates`] of the sub-triangles' ordinates `b` of a function of
/// vertex `k` ([`hermite_ordinates`] with Hermite data at `V_k` only). `None` if
/// an ordinate taken as zero is not `+0.0` or two copies of one differ (Hermite
/// data at another vertex).
pub fn compact(b: &[[f64; 6]; 6], k: usize) -> Option<VertexOrdinates> {
    let mut kept = [f64::NAN; 9];
    for (s, places) in PLACES[k].iter().enumerate() {
        for (j, &place) in places.iter().enumerate() {
            match place {
                ZERO if b[s][j].to_bits() != 0 => return None,
                ZERO => {}
                _ => kept[place as usize] = b[s][j],
            }
        }
    }
    (0..6)
        .all(|s| expand(&kept, k, s).map(f64::to_bits) == b[s].map(f64::to_bits))
        .then_some(kept)
}

/// The ordinates of sub-triangle `s` (in [`BERNSTEIN_ORDER`]) of a function of
/// vertex `k` kept as `kept`: [`hermite_ordinates`]' `b[s]`, bit for bit.
#[inline(always)]
pub fn expand(kept: &VertexOrdinates, k: usize, s: usize) -> [f64; 6] {
    PLACES[k][s].map(|place| match place {
        ZERO => 0.0,
        _ => kept[place as usize],
    })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::barycentric;
    use crate::rng::SplitMix64;

    /// The kept ordinates give back every sub-triangle's ordinates bit for bit, for
    /// Hermite data at each vertex alone, and refuse data at two vertices.
    #[test]
    fn kept_ordinates_expand_to_the_hermite_ordinates_bit_for_bit() {
        let mut rng = SplitMix64(11);
        for _ in 0..200 {
            let tri = random_geometry(&mut rng);
            for k in 0..3 {
                let mut f = [0.0; 3];
                let mut g = [Vec2::zeros(); 3];
                f[k] = rng.next_f64() - 0.3;
                g[k] = Vec2::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5) * 4.0;
                let b = hermite_ordinates(&tri, f, g);
                let kept = compact(&b, k).expect("data at one vertex is kept");
                for (s, b) in b.iter().enumerate() {
                    assert_eq!(expand(&kept, k, s).map(f64::to_bits), b.map(f64::to_bits));
                }
                // 16 of the 36 sub-triangle ordinates are the 10 zero ones.
                let zeros = b.iter().flatten().filter(|v| v.to_bits() == 0).count();
                assert!(zeros >= 16, "{zeros} zero ordinates");
                f[(k + 1) % 3] = 0.5;
                assert!(compact(&hermite_ordinates(&tri, f, g), k).is_none());
            }
        }
    }

    /// Value and gradient at `x` of the quadratic with ordinates `b` on the triangle
    /// `p` (extended outside it).
    fn eval(p: &[Vec2; 3], b: &[f64; 6], x: Vec2) -> (f64, Vec2) {
        let tau = barycentric(p[0], p[1], p[2], x);
        let d = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
        // ∇τ_k = perp(P_{k+2} − P_{k+1}) / d.
        let grad_tau: [Vec2; 3] = std::array::from_fn(|k| {
            let e = p[(k + 2) % 3] - p[(k + 1) % 3];
            Vec2::new(-e.y, e.x) / d
        });
        let (bb, db) = bernstein(tau);
        let mut value = 0.0;
        let mut grad = Vec2::zeros();
        for k in 0..6 {
            value += b[k] * bb[k];
            for m in 0..3 {
                grad += grad_tau[m] * (b[k] * db[k][m]);
            }
        }
        (value, grad)
    }

    /// A random counter-clockwise triangle with a random interior split point and
    /// random edge points (not the PS-consistent ones: the identities tested here hold
    /// for any split point inside and edge points on the edges).
    fn random_geometry(rng: &mut SplitMix64) -> MainTriangle {
        loop {
            let v: [Vec2; 3] =
                std::array::from_fn(|_| Vec2::new(rng.next_f64(), rng.next_f64()) * 2.0);
            let area = crate::mesh::signed_area(v[0], v[1], v[2]);
            if area < 0.05 {
                continue;
            }
            let w: [f64; 3] = std::array::from_fn(|_| 0.2 + rng.next_f64());
            let s = w.iter().sum::<f64>();
            let z_bary = w.map(|x| x / s);
            let r_lambda: [f64; 3] = std::array::from_fn(|_| 0.15 + 0.7 * rng.next_f64());
            return MainTriangle {
                v,
                z: v[0] * z_bary[0] + v[1] * z_bary[1] + v[2] * z_bary[2],
                z_bary,
                r: std::array::from_fn(|m| {
                    v[m] * r_lambda[m] + v[(m + 1) % 3] * (1.0 - r_lambda[m])
                }),
                r_lambda,
            };
        }
    }

    fn sub_triangles(tri: &MainTriangle) -> [[Vec2; 3]; 6] {
        let mut out = [[Vec2::zeros(); 3]; 6];
        for m in 0..3 {
            out[2 * m] = [tri.v[m], tri.r[m], tri.z];
            out[2 * m + 1] = [tri.r[m], tri.v[(m + 1) % 3], tri.z];
        }
        out
    }

    #[test]
    fn bernstein_polynomials_sum_to_one_and_their_derivatives_to_two() {
        let (b, db) = bernstein([0.2f64, 0.3, 0.5]);
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        for m in 0..3 {
            // Σ_k ∂B_k/∂τ_m = 2 (τ_0 + τ_1 + τ_2) = 2.
            assert!((db.iter().map(|d| d[m]).sum::<f64>() - 2.0).abs() < 1e-15);
        }
    }

    #[test]
    fn hermite_interpolant_reproduces_quadratics() {
        let mut rng = SplitMix64(7);
        for _ in 0..50 {
            let tri = random_geometry(&mut rng);
            let c: [f64; 6] = std::array::from_fn(|_| 2.0 * rng.next_f64() - 1.0);
            let p = |x: Vec2| {
                c[0] + c[1] * x.x
                    + c[2] * x.y
                    + c[3] * x.x * x.x
                    + c[4] * x.x * x.y
                    + c[5] * x.y * x.y
            };
            let dp = |x: Vec2| {
                Vec2::new(
                    c[1] + 2.0 * c[3] * x.x + c[4] * x.y,
                    c[2] + c[4] * x.x + 2.0 * c[5] * x.y,
                )
            };
            let b = hermite_ordinates(&tri, tri.v.map(p), tri.v.map(dp));
            for (s, corners) in sub_triangles(&tri).iter().enumerate() {
                for w in [
                    [0.2, 0.3, 0.5],
                    [0.7, 0.2, 0.1],
                    [1.0, 0.0, 0.0],
                    [0.0, 0.5, 0.5],
                ] {
                    let x = corners[0] * w[0] + corners[1] * w[1] + corners[2] * w[2];
                    let (value, grad) = eval(corners, &b[s], x);
                    assert!((value - p(x)).abs() < 1e-13, "sub {s}: {value} vs {}", p(x));
                    assert!((grad - dp(x)).norm() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn hermite_interpolant_matches_the_vertex_data_and_is_c1_inside() {
        let mut rng = SplitMix64(11);
        for _ in 0..50 {
            let tri = random_geometry(&mut rng);
            let f: [f64; 3] = std::array::from_fn(|_| rng.next_f64());
            let g: [Vec2; 3] = std::array::from_fn(|_| Vec2::new(rng.next_f64(), rng.next_f64()));
            let b = hermite_ordinates(&tri, f, g);
            let subs = sub_triangles(&tri);
            for m in 0..3 {
                // Both sub-triangles at V_m interpolate f_m and g_m.
                for s in [2 * m, 2 * ((m + 2) % 3) + 1] {
                    let (value, grad) = eval(&subs[s], &b[s], tri.v[m]);
                    assert!((value - f[m]).abs() < 1e-14);
                    assert!((grad - g[m]).norm() < 1e-12);
                }
                // C¹ across the inner sub-edges R_m–Z and V_m–Z.
                for (s1, s2, p, q) in [
                    (2 * m, 2 * m + 1, tri.r[m], tri.z),
                    (2 * m, 2 * ((m + 2) % 3) + 1, tri.v[m], tri.z),
                ] {
                    for w in [0.0, 0.3, 0.6, 1.0] {
                        let x = p + (q - p) * w;
                        let (v1, g1) = eval(&subs[s1], &b[s1], x);
                        let (v2, g2) = eval(&subs[s2], &b[s2], x);
                        assert!((v1 - v2).abs() < 1e-14);
                        assert!((g1 - g2).norm() < 1e-12, "{g1:?} vs {g2:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn vertex_function_ordinates_are_the_papers_eqs_37_38() {
        // φ with value α and gradient g at V_1 (local 0), zero data elsewhere:
        // L = α + (1 − λ_1)/2 β̄ at M_12, L' = α + (1 − ν_1)/2 γ̄ at M_13,
        // L̃ = α + b/2 β̄ + c/2 γ̄ at S_1, λ_1 L at R_12, ν_1 L' at R_13,
        // λ_1 L̃ at T_12, ν_1 L̃ at T_13, a L̃ at Z, with β̄ = g·(V_2 − V_1),
        // γ̄ = g·(V_3 − V_1), R_12 = λ_1 V_1 + (1 − λ_1) V_2, R_13 = ν_1 V_1 + (1 − ν_1) V_3.
        let mut rng = SplitMix64(3);
        let tri = random_geometry(&mut rng);
        let (alpha, g) = (0.4, Vec2::new(0.7, -1.3));
        let b = hermite_ordinates(&tri, [alpha, 0.0, 0.0], [g, Vec2::zeros(), Vec2::zeros()]);
        let [za, zb, zc] = tri.z_bary;
        let lambda1 = tri.r_lambda[0];
        // Local edge 2 joins V_3 and V_1: the weight of V_1 in R_13 is 1 − λ_2.
        let nu1 = 1.0 - tri.r_lambda[2];
        let beta_bar = g.dot(&(tri.v[1] - tri.v[0]));
        let gamma_bar = g.dot(&(tri.v[2] - tri.v[0]));
        let l = alpha + (1.0 - lambda1) / 2.0 * beta_bar;
        let l_prime = alpha + (1.0 - nu1) / 2.0 * gamma_bar;
        let l_tilde = alpha + zb / 2.0 * beta_bar + zc / 2.0 * gamma_bar;
        // Sub-triangle 0 = (V_1, R_12, Z): b200 b020 b002 b110 b011 b101.
        let expected0 = [
            alpha,
            lambda1 * l,
            za * l_tilde,
            l,
            lambda1 * l_tilde,
            l_tilde,
        ];
        // Sub-triangle 5 = (R_31, V_1, Z).
        let expected5 = [
            nu1 * l_prime,
            alpha,
            za * l_tilde,
            l_prime,
            l_tilde,
            nu1 * l_tilde,
        ];
        for k in 0..6 {
            assert!(
                (b[0][k] - expected0[k]).abs() < 1e-14,
                "sub 0, {}",
                BERNSTEIN_ORDER[k]
            );
            assert!(
                (b[5][k] - expected5[k]).abs() < 1e-14,
                "sub 5, {}",
                BERNSTEIN_ORDER[k]
            );
        }
        // Sub-triangles 2 and 3 (on the edge V_2–V_3, away from V_1): only the
        // ordinate at Z is non-zero (T_23 mixes S_2 and S_3, both zero).
        for s in [2, 3] {
            for (k, ordinate) in b[s].iter().enumerate() {
                let expect = if k == 2 { za * l_tilde } else { 0.0 };
                assert!((ordinate - expect).abs() < 1e-14);
            }
        }
    }
}
