//! The seeds' printed numbers that the studies and the tests compare against, in
//! one place, each with where it is printed. Only numbers that psmpm reproduces or
//! explains are kept here; `docs/results.md` says which ones and how closely.

use crate::bases::BasisKind;

/// B2, the vibrating bar at small deformation: the displacement error E_u at
/// `t_end` printed in thesis Table 4.2 (PS) and Table 4.3 (PL), three significant
/// digits, as `(basis, n_x, E_u)` with `n_x` the number of block columns plus one
/// (the thesis' nodes along the bar).
pub const THESIS_TABLES_4_2_AND_4_3: [(BasisKind, usize, f64); 9] = [
    (BasisKind::Ps, 2, 3.71e-4),
    (BasisKind::Ps, 3, 3.14e-5),
    (BasisKind::Ps, 5, 3.57e-6),
    (BasisKind::Ps, 9, 4.90e-7),
    (BasisKind::Ps, 17, 1.77e-7),
    (BasisKind::Pl, 5, 1.81e-4),
    (BasisKind::Pl, 9, 4.44e-5),
    (BasisKind::Pl, 17, 1.08e-5),
    (BasisKind::Pl, 33, 2.68e-6),
];

/// The printed E_u of thesis Tables 4.2–4.3 for `basis` on `n_x`, if printed.
pub fn thesis_b2_error(basis: BasisKind, n_x: usize) -> Option<f64> {
    THESIS_TABLES_4_2_AND_4_3
        .iter()
        .find(|&&(b, n, _)| b == basis && n == n_x)
        .map(|&(_, _, e)| e)
}
