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

/// `vertical` or `horizontal`.
pub fn mirror_line_to_str(m: MirrorAxis) -> &'static str {
    match m {
        MirrorAxis::Vertical => "vertical",
        MirrorAxis::Horizontal => "horizontal",
    }
}

/// Parses `vertical` or `horizontal`.
pub fn parse_mirror_line(name: &str) -> Result<MirrorAxis, String> {
    match name {
        "vertical" => Ok(MirrorAxis::Vertical),
        "horizontal" => Ok(MirrorAxis::Horizontal),
        other => Err(format!(
            "unknown mirror line `{}` (known: vertical, horizontal)",
            super::limits::echo(other)
        )),
    }
}

/// `true` for the default mirror line (left out when a scene is written).
pub(super) fn is_vertical(m: &MirrorAxis) -> bool {
    *m == MirrorAxis::Vertical
}
