//! How bases, mass strategies, split points and mirror lines are named in scene
//! files.

use psmpm_basis::basis::powell_sabin::{MirrorAxis, SplitPoint};

pub(super) mod basis_name {
    use crate::bases::BasisKind;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(b: &BasisKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(b.name())
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<BasisKind, D::Error> {
        let name = String::deserialize(d)?;
        BasisKind::parse(&name).map_err(serde::de::Error::custom)
    }
}

pub(super) mod mass_name {
    use crate::mass::MassKind;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(m: &MassKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&m.spec())
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<MassKind, D::Error> {
        let name = String::deserialize(d)?;
        MassKind::parse(&name).map_err(serde::de::Error::custom)
    }
}

pub(super) mod split_name {
    use psmpm_basis::basis::powell_sabin::SplitPoint;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(p: &SplitPoint, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(super::split_to_str(*p))
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<SplitPoint, D::Error> {
        let name = String::deserialize(d)?;
        super::parse_split(&name).map_err(serde::de::Error::custom)
    }
}

/// `incentre` or `centroid`.
pub fn split_to_str(p: SplitPoint) -> &'static str {
    match p {
        SplitPoint::Centroid => "centroid",
        _ => "incentre",
    }
}

/// Parses `incentre` or `centroid`.
pub fn parse_split(name: &str) -> Result<SplitPoint, String> {
    match name {
        "incentre" => Ok(SplitPoint::Incentre),
        "centroid" => Ok(SplitPoint::Centroid),
        other => Err(format!(
            "unknown split point `{}` (known: incentre, centroid)",
            super::limits::echo(other)
        )),
    }
}

pub(super) mod mirror_line_name {
    use psmpm_basis::basis::powell_sabin::MirrorAxis;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(m: &MirrorAxis, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(super::mirror_line_to_str(*m))
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<MirrorAxis, D::Error> {
        let name = String::deserialize(d)?;
        super::parse_mirror_line(&name).map_err(serde::de::Error::custom)
    }
}

/// `vertical`, `horizontal`, `diagonal` or `anti-diagonal`.
pub fn mirror_line_to_str(m: MirrorAxis) -> &'static str {
    match m {
        MirrorAxis::Vertical => "vertical",
        MirrorAxis::Horizontal => "horizontal",
        MirrorAxis::Diagonal => "diagonal",
        MirrorAxis::AntiDiagonal => "anti-diagonal",
    }
}

/// Parses `vertical`, `horizontal`, `diagonal` or `anti-diagonal`.
pub fn parse_mirror_line(name: &str) -> Result<MirrorAxis, String> {
    match name {
        "vertical" => Ok(MirrorAxis::Vertical),
        "horizontal" => Ok(MirrorAxis::Horizontal),
        "diagonal" => Ok(MirrorAxis::Diagonal),
        "anti-diagonal" => Ok(MirrorAxis::AntiDiagonal),
        other => Err(format!(
            "unknown mirror line `{}` (known: vertical, horizontal, diagonal, anti-diagonal)",
            super::limits::echo(other)
        )),
    }
}

/// `true` for the default mirror line (left out when a scene is written).
pub(super) fn is_vertical(m: &MirrorAxis) -> bool {
    *m == MirrorAxis::Vertical
}

/// `message` with a suggestion for a name it rejects, when one of the names it
/// lists is close (a typo, a transposition, another case or a missing `-`):
/// `unknown field `yuong` (did you mean `young`?), expected one of …`. Reads the
/// parser's `unknown field|variant `X`, expected one of `a`, `b`, …` and the
/// scene's own `unknown … `X` (known: a, b, …)`; any other message is returned
/// as it is, and so is one that already suggests.
pub(crate) fn did_you_mean(message: String) -> String {
    if message.contains("(did you mean") {
        return message;
    }
    let Some(start) = message.find("unknown ") else {
        return message;
    };
    let rest = &message[start..];
    let Some(open) = rest.find('`') else {
        return message;
    };
    let Some(close) = rest[open + 1..].find('`').map(|c| open + 1 + c) else {
        return message;
    };
    let name = &rest[open + 1..close];
    let after = &rest[close + 1..];
    let candidates: Vec<&str> = if let Some(list) = after.strip_prefix(" (known: ") {
        list.split(')')
            .next()
            .unwrap_or("")
            .split(", ")
            // `partial:TAU`, `extended-hybrid-apic[:C1:C2]`: the name alone.
            .map(|c| c.split([':', '[']).next().unwrap_or(c))
            .collect()
    } else if after.starts_with(", expected") || after.starts_with("; the mesh has tags") {
        after.split('`').skip(1).step_by(2).collect()
    } else {
        return message;
    };
    let Some(best) = closest(name, &candidates) else {
        return message;
    };
    let at = start + close + 1;
    format!(
        "{} (did you mean `{best}`?){}",
        &message[..at],
        &message[at..]
    )
}

/// The candidate nearest to `name` by the optimal string alignment distance
/// (edits and transpositions), compared in lower case without `-`, `_` and
/// spaces, when it is near enough to be a typo: none for names of up to 2
/// letters (`nx` is not `x`), 1 edit up to 5 (`pll` is `pl`), 2 up to 9, 3
/// beyond; else the
/// longest candidate of 4 letters or more that `name` starts with (a long form,
/// `youngs_modulus`), or the one `name` is the plural of (`bodies`); `None` for
/// none, or for `name` itself.
fn closest<'a>(name: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let plain = |s: &str| -> String {
        s.chars()
            .filter(|c| !matches!(c, '-' | '_' | ' '))
            .flat_map(char::to_lowercase)
            .collect()
    };
    let wanted = plain(name);
    let allowed = match wanted.chars().count() {
        0..=2 => 0,
        3..=5 => 1,
        6..=9 => 2,
        _ => 3,
    };
    let near = candidates
        .iter()
        .filter(|c| !c.is_empty() && **c != name)
        .map(|c| (strsim::osa_distance(&wanted, &plain(c)), *c))
        .filter(|(d, _)| *d <= allowed)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c);
    // A plural of a name (`[[bodies]]`, `effects`): the candidate it is the plural of.
    let plural = || {
        candidates.iter().copied().find(|c| {
            let c = plain(c);
            wanted == format!("{c}s")
                || wanted == format!("{c}es")
                || c.strip_suffix('y')
                    .is_some_and(|stem| wanted == format!("{stem}ies"))
        })
    };
    // An abbreviation of a name (`norm` for `normal`): the one candidate that
    // starts with a name of 3 letters or more.
    let abbreviated = || {
        let mut longer = candidates.iter().copied().filter(|c| {
            let c = plain(c);
            wanted.chars().count() >= 3 && c.len() > wanted.len() && c.starts_with(&wanted)
        });
        let first = longer.next()?;
        longer.next().is_none().then_some(first)
    };
    // A long form of a name (`youngs_modulus`, `poisson_ratio`): the longest
    // candidate of 4 letters or more that the name starts with.
    near.or_else(plural).or_else(abbreviated).or_else(|| {
        candidates
            .iter()
            .filter(|c| **c != name)
            .filter(|c| {
                let c = plain(c);
                c.chars().count() >= 4 && wanted.starts_with(&c)
            })
            .max_by_key(|c| plain(c).chars().count())
            .copied()
    })
}

#[cfg(test)]
mod tests {
    use super::did_you_mean;

    /// The typos a user made (and a few more) get the name they meant; names
    /// far from every candidate, and other messages, are left alone.
    #[test]
    fn a_misspelt_name_gets_the_nearest_known_one() {
        let cases = [
            (
                "unknown field `yuong`, expected one of `model`, `young`, `poisson`, `density`",
                "unknown field `yuong` (did you mean `young`?), expected one of `model`, `young`, `poisson`, `density`",
            ),
            (
                "unknown variant `neohookean`, expected one of `linear-elastic`, `paper-linear`, `corotated`, `corotational`, `neo-hookean`",
                "unknown variant `neohookean` (did you mean `neo-hookean`?), expected one of",
            ),
            (
                "unknown field `radious`, expected one of `shape`, `centre`, `radius`",
                "(did you mean `radius`?)",
            ),
            (
                "unknown field `youngs_modulus`, expected one of `model`, `young`, `poisson`, `density`",
                "unknown field `youngs_modulus` (did you mean `young`?)",
            ),
            (
                "unknown field `poisson_ratio`, expected one of `model`, `young`, `poisson`, `density`",
                "(did you mean `poisson`?)",
            ),
            (
                "unknown field `bodies`, expected one of `name`, `dim`, `body`, `time`",
                "unknown field `bodies` (did you mean `body`?), expected one of",
            ),
            (
                "unknown basis `pll` (known: ps, pl, bspline, pl1d)",
                "unknown basis `pll` (did you mean `pl`?) (known: ps, pl, bspline, pl1d)",
            ),
            (
                "unknown basis `PS` (known: ps, pl, bspline, pl1d)",
                "unknown basis `PS` (did you mean `ps`?) (known: ps, pl, bspline, pl1d)",
            ),
            (
                "unknown mass strategy `lumpd` (known: default, consistent, lumped, partial, partial:TAU, extended-hybrid-apic[:C1:C2], fmpm:K)",
                "(did you mean `lumped`?)",
            ),
            (
                "unknown variant `gravit`, expected one of `gravity`, `damping`, `traction`",
                "(did you mean `gravity`?)",
            ),
            (
                "unknown variant `block`, expected `blocks` or `polygon`",
                "(did you mean `blocks`?)",
            ),
            (
                "unknown boundary tag `Ramp`; the mesh has tags `ramp`, `walls`, `top`",
                "unknown boundary tag `Ramp` (did you mean `ramp`?); the mesh has tags",
            ),
            // An abbreviation a student wrote (`fix = ["norm"]`).
            (
                "unknown variant `norm`, expected one of `x`, `y`, `normal`",
                "unknown variant `norm` (did you mean `normal`?), expected one of",
            ),
        ];
        for (message, part) in cases {
            let out = did_you_mean(message.to_string());
            assert!(out.contains(part), "`{part}` not in: {out}");
            // Once only.
            assert_eq!(did_you_mean(out.clone()), out);
        }
        for message in [
            "unknown field `colour`, expected one of `model`, `young`",
            "unknown field `nx`, expected one of `x`, `y`, `blocks`, `layout`",
            // A prefix of two candidates names neither.
            "unknown variant `gra`, expected one of `gravity`, `graded`",
            "unknown basis `bezier` (known: ps, pl, bspline, pl1d)",
            "expected a number",
            "unknown field `x",
        ] {
            assert_eq!(did_you_mean(message.to_string()), message);
        }
    }
}
