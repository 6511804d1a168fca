//! The material of every particle: one law for all particles (any [`Material`]), or
//! a table of laws with the law of each particle ([`MaterialTable`]), for scenes
//! whose bodies have their own materials.
//!
//! The driver asks for the stress and energy of particle `p` ([`ParticleMaterials`]);
//! a single law ignores `p`. The table looks the law up per particle, except when
//! it holds one law, where it skips the lookup (so a single-material scene pays one
//! predictable branch per particle).

use crate::material::{AnyMaterial, Corotational, Elastic, LinearElastic, Material, NeoHookean};
use crate::sparse::Scalar;
use nalgebra::SMatrix;

/// The constitutive law of each particle.
pub trait ParticleMaterials<T: Scalar, const D: usize>: Sync {
    /// Cauchy stress `σ(F)` of particle `p`.
    fn stress(&self, p: usize, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D>;
    /// Strain-energy density per unit reference volume `W(F)` of particle `p`.
    fn energy_density(&self, p: usize, f: &SMatrix<T, D, D>) -> T;
    /// The elastic constants of particle `p` (for the small-strain stiffness of the
    /// critical time step).
    fn elastic(&self, p: usize) -> &Elastic;
    /// Whether the law of particle `p` is objective ([`Material::is_objective`]).
    fn is_objective(&self, p: usize) -> bool {
        let _ = p;
        true
    }
}

/// One law for every particle: each law of [`crate::material`] (a blanket impl over
/// [`Material`] would overlap the table's).
macro_rules! one_law_for_all {
    ($($law:ty),*) => {$(
        impl<T: Scalar, const D: usize> ParticleMaterials<T, D> for $law {
            #[inline]
            fn stress(&self, _p: usize, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
                Material::stress(self, f)
            }
            #[inline]
            fn energy_density(&self, _p: usize, f: &SMatrix<T, D, D>) -> T {
                Material::energy_density(self, f)
            }
            #[inline]
            fn elastic(&self, _p: usize) -> &Elastic {
                Material::<T, D>::elastic(self)
            }
            #[inline]
            fn is_objective(&self, _p: usize) -> bool {
                Material::<T, D>::is_objective(self)
            }
        }
    )*};
}

one_law_for_all!(LinearElastic, NeoHookean, Corotational, AnyMaterial);

/// Distinct laws and the law of each particle (the materials of a scene's bodies).
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialTable {
    laws: Vec<AnyMaterial>,
    /// Index into `laws` per particle; empty when there is one law.
    law_of: Vec<u32>,
}

/// A particle's law index that is not in the table.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "particle {particle} has law {law}, but the table has {}",
    crate::scene::limits::plural(*laws, "law", "laws")
)]
pub struct TableError {
    /// The particle.
    pub particle: usize,
    /// Its law index.
    pub law: usize,
    /// Laws in the table.
    pub laws: usize,
}

impl MaterialTable {
    /// The law `law` for every particle.
    pub fn uniform(law: AnyMaterial) -> Self {
        MaterialTable {
            laws: vec![law],
            law_of: Vec::new(),
        }
    }

    /// `laws[law_of[p]]` for particle `p`; equal laws are merged, and one law left
    /// makes the table [`MaterialTable::uniform`].
    pub fn new(laws: &[AnyMaterial], law_of: &[usize]) -> Result<Self, TableError> {
        let Some(&first) = laws.first() else {
            return Err(TableError {
                particle: 0,
                law: 0,
                laws: 0,
            });
        };
        if let Some((particle, &law)) = law_of.iter().enumerate().find(|(_, &l)| l >= laws.len()) {
            return Err(TableError {
                particle,
                law,
                laws: laws.len(),
            });
        }
        let mut distinct: Vec<AnyMaterial> = Vec::new();
        let mut merged = Vec::with_capacity(laws.len());
        for law in laws {
            match distinct.iter().position(|d| d == law) {
                Some(i) => merged.push(i as u32),
                None => {
                    merged.push(distinct.len() as u32);
                    distinct.push(*law);
                }
            }
        }
        let used: Vec<u32> = law_of.iter().map(|&l| merged[l]).collect();
        if distinct.len() <= 1 || used.windows(2).all(|w| w[0] == w[1]) {
            let one = used.first().map_or(0, |&l| l as usize);
            return Ok(MaterialTable::uniform(*distinct.get(one).unwrap_or(&first)));
        }
        Ok(MaterialTable {
            laws: distinct,
            law_of: used,
        })
    }

    /// The distinct laws.
    pub fn laws(&self) -> &[AnyMaterial] {
        &self.laws
    }

    /// The law of particle `p`.
    #[inline]
    pub fn law(&self, p: usize) -> &AnyMaterial {
        match self.law_of.get(p) {
            Some(&l) => &self.laws[l as usize],
            None => &self.laws[0],
        }
    }

    /// The largest rotation angle of the particles whose law is not objective (the
    /// paper's `linear-elastic`), 0 when no particle has such a law; `all` is the
    /// largest angle of all particles ([`crate::material::max_rotation`] of `fs`),
    /// the answer when every particle has such a law.
    pub fn max_rotation_of_non_objective<T: Scalar, const D: usize>(
        &self,
        fs: &[SMatrix<T, D, D>],
        all: f64,
    ) -> f64 {
        if self.laws.iter().all(|l| l.is_objective()) {
            0.0
        } else if self.law_of.is_empty() {
            all
        } else {
            fs.iter()
                .enumerate()
                .filter(|(p, _)| !self.law(*p).is_objective())
                .map(|(_, f)| crate::material::rotation_angle(f))
                .fold(0.0, f64::max)
        }
    }
}

impl<T: Scalar, const D: usize> ParticleMaterials<T, D> for MaterialTable {
    #[inline]
    fn stress(&self, p: usize, f: &SMatrix<T, D, D>) -> SMatrix<T, D, D> {
        Material::<T, D>::stress(self.law(p), f)
    }
    #[inline]
    fn energy_density(&self, p: usize, f: &SMatrix<T, D, D>) -> T {
        Material::<T, D>::energy_density(self.law(p), f)
    }
    #[inline]
    fn elastic(&self, p: usize) -> &Elastic {
        Material::<T, D>::elastic(self.law(p))
    }
    #[inline]
    fn is_objective(&self, p: usize) -> bool {
        self.law(p).is_objective()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix2;

    #[test]
    fn the_table_gives_each_particle_its_law_and_merges_equal_laws() {
        let soft =
            AnyMaterial::Corotational(Corotational::new(Elastic::new(1.0, 0.3, 1.0).unwrap(), 2));
        let stiff = AnyMaterial::Linear(LinearElastic::new(
            Elastic::new(100.0, 0.3, 1.0).unwrap(),
            2,
        ));
        let table = MaterialTable::new(&[soft, stiff, soft], &[0, 1, 2, 1]).unwrap();
        assert_eq!(table.laws().len(), 2);
        let f = Matrix2::new(1.01, 0.0, 0.0, 1.0);
        let s = |p| ParticleMaterials::<f64, 2>::stress(&table, p, &f);
        assert_eq!(s(0), Material::<f64, 2>::stress(&soft, &f));
        assert_eq!(s(1), Material::<f64, 2>::stress(&stiff, &f));
        assert_eq!(s(2), s(0));
        // The strain energy of each particle is that of its own law.
        let w = |p| ParticleMaterials::<f64, 2>::energy_density(&table, p, &f);
        assert_eq!(w(0), Material::<f64, 2>::energy_density(&soft, &f));
        assert_eq!(w(1), Material::<f64, 2>::energy_density(&stiff, &f));
        assert!(w(1) > 50.0 * w(0));
        assert_eq!(ParticleMaterials::<f64, 2>::elastic(&table, 3).young, 100.0);
        // One law in use: no per-particle lookup.
        assert_eq!(
            MaterialTable::new(&[soft, soft], &[0, 1]).unwrap(),
            MaterialTable::uniform(soft)
        );
        assert_eq!(
            MaterialTable::new(&[soft, stiff], &[1, 1]).unwrap(),
            MaterialTable::uniform(stiff)
        );
        assert!(MaterialTable::new(&[soft], &[0, 1]).is_err());
        // Only the paper's law's particles count for the rotation warning.
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let turned = Matrix2::new(c, -s, s, c);
        let fs = [turned, Matrix2::identity(), turned, Matrix2::identity()];
        assert_eq!(table.max_rotation_of_non_objective(&fs, 0.3), 0.0);
        let fs = [
            Matrix2::identity(),
            turned,
            Matrix2::identity(),
            Matrix2::identity(),
        ];
        assert!((table.max_rotation_of_non_objective(&fs, 0.3) - 0.3).abs() < 1e-12);
        assert_eq!(
            MaterialTable::uniform(stiff).max_rotation_of_non_objective(&fs, 0.3),
            0.3
        );
        assert_eq!(
            MaterialTable::uniform(soft).max_rotation_of_non_objective(&fs, 0.3),
            0.0
        );
        assert!(MaterialTable::new(&[], &[]).is_err());
    }
}
