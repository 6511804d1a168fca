//! The built-in scenes: TOML files under `scenes/` compiled into the library.

use super::Scene;

/// The built-in scenes: name, one line, TOML text.
pub const BUILTIN: [(&str, &str, &str); 10] = [
    (
        "vibrating-bar",
        "B2: elastic bar L = 25, H = 2 vibrating in its first mode (v0 = 0.1)",
        include_str!("../../scenes/vibrating-bar.toml"),
    ),
    (
        "vibrating-bar-thesis",
        "B2 as the thesis computed its tables (centroids, Delaunay blocks, 1999 steps)",
        include_str!("../../scenes/vibrating-bar-thesis.toml"),
    ),
    (
        "column-small",
        "B5a: elastic column H = 25, W = 2 settling under self-weight",
        include_str!("../../scenes/column-small.toml"),
    ),
    (
        "axis-aligned",
        "B4: neo-Hookean manufactured solution on an unstructured unit square",
        include_str!("../../scenes/axis-aligned.toml"),
    ),
    (
        "bar-large",
        "B3: bar L = 1, W = 0.05 in its first mode at 7 % strain (the paper's variant), to t = 20",
        include_str!("../../scenes/bar-large.toml"),
    ),
    (
        "bar-large-thesis",
        "B3 as in the thesis: L = 25, H = 2, PS 8 x 1 blocks (78 functions, 20 ppe), to t = 20",
        include_str!("../../scenes/bar-large-thesis.toml"),
    ),
    (
        "column-large",
        "B5b: column H = 1, W = 0.1 at 18 % strain, one empty block row above, to t = 2.5",
        include_str!("../../scenes/column-large.toml"),
    ),
    (
        "column-damped",
        "B5c: the B5b column with local damping (alpha = 0.6) settling to equilibrium, to t = 10",
        include_str!("../../scenes/column-damped.toml"),
    ),
    (
        "vibrating-bar-1d",
        "B2 in 1D (quadratic B-spline or 1D PL)",
        include_str!("../../scenes/vibrating-bar-1d.toml"),
    ),
    (
        "column-small-1d",
        "B5a in 1D (quadratic B-spline or 1D PL)",
        include_str!("../../scenes/column-small-1d.toml"),
    ),
];

impl Scene {
    /// The built-in scene `name`. The error lists the known scenes.
    pub fn builtin(name: &str) -> Result<Self, String> {
        let (_, _, text) = BUILTIN.iter().find(|(n, _, _)| *n == name).ok_or_else(|| {
            let known: Vec<&str> = BUILTIN.iter().map(|(n, _, _)| *n).collect();
            super::names::did_you_mean(format!(
                "unknown scene `{}` (known: {})",
                super::limits::echo(name),
                known.join(", ")
            ))
        })?;
        Scene::from_toml(text, &format!("scenes/{name}.toml")).map_err(|e| e.to_string())
    }
}
