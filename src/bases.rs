//! The typed choice of basis made at the edge (command line, scene file), and
//! how each choice is built from a mesh.
//!
//! Strings become a [`BasisKind`] once, when input is parsed; from there on
//! the code is monomorphised over the concrete basis type.

use psmpm_basis::basis::linear::Linear;
use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm_basis::{BasisError, Real, TriMesh};
use serde::Serialize;

/// The bases of psmpm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BasisKind {
    /// Quadratic Powell–Sabin splines on triangles (C¹).
    Ps,
    /// Piecewise-linear Lagrange on triangles (C⁰).
    Pl,
    /// Quadratic B-splines in 1D (C¹).
    Bspline,
    /// Piecewise-linear Lagrange in 1D.
    Pl1d,
}

impl BasisKind {
    /// All kinds, in the order they are listed to users.
    pub const ALL: [BasisKind; 4] = [
        BasisKind::Ps,
        BasisKind::Pl,
        BasisKind::Bspline,
        BasisKind::Pl1d,
    ];

    /// The name used on the command line and in output.
    pub fn name(self) -> &'static str {
        match self {
            BasisKind::Ps => "ps",
            BasisKind::Pl => "pl",
            BasisKind::Bspline => "bspline",
            BasisKind::Pl1d => "pl1d",
        }
    }

    /// Parses a name; the error lists the known names.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| {
                let known: Vec<_> = Self::ALL.iter().map(|k| k.name()).collect();
                crate::scene::names::did_you_mean(format!(
                    "unknown basis `{}` (known: {})",
                    crate::scene::limits::echo(name),
                    known.join(", ")
                ))
            })
    }

    /// The length that sets the time step of a Courant-number guess on a mesh with
    /// smallest edge `h`: the PS refinement splits every edge, so its elements are
    /// about `h / 2`; the other bases use `h`.
    pub fn wave_length(self, h: f64) -> f64 {
        match self {
            BasisKind::Ps => 0.5 * h,
            BasisKind::Pl | BasisKind::Bspline | BasisKind::Pl1d => h,
        }
    }

    /// Spatial dimension of the basis.
    pub fn dim(self) -> usize {
        match self {
            BasisKind::Ps | BasisKind::Pl => 2,
            BasisKind::Bspline | BasisKind::Pl1d => 1,
        }
    }
}

/// Builds the piecewise-linear basis on `mesh`.
pub fn linear<T: Real>(mesh: TriMesh) -> Result<Linear<T>, BasisError> {
    Ok(Linear::new(mesh))
}

/// Builds the Powell–Sabin basis on `mesh` with incentre split points.
pub fn powell_sabin<T: Real>(mesh: TriMesh) -> Result<PowellSabin<T>, BasisError> {
    PowellSabin::new(mesh, SplitPoint::Incentre)
}
