//! Names of the library's option enums (modes, return models, gaze
//! formats, the simulator's variants, geometries, detectors, arrivals and
//! samplings): one table per enum, [`Named::TABLE`], behind its `name()`,
//! `Display`, `FromStr` and serde, which the command line (its flags' values
//! and help) and the Python binding read too. No enum writes its names twice.

use thiserror::Error;

/// An enum of a few named values, with one table of names.
pub trait Named: Sized + Copy + 'static {
    /// Every value, its name and a one-line description, in the order
    /// listed to users.
    const TABLE: &'static [(Self, &'static str, &'static str)];
    /// The names alone, in the table's order.
    const NAMES: &'static [&'static str];
}

/// A name that no value of the enum has: `'given' is not one of a, b, c`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("'{given}' is not one of {}", names.join(", "))]
pub struct UnknownName {
    /// The name given.
    pub given: String,
    /// The enum's names.
    pub names: &'static [&'static str],
}

/// The value named `name` in `T`'s table.
///
/// # Errors
/// [`UnknownName`] when no value has that name.
pub fn parse<T: Named>(name: &str) -> Result<T, UnknownName> {
    T::TABLE
        .iter()
        .find(|(_, n, _)| *n == name)
        .map(|&(v, _, _)| v)
        .ok_or_else(|| UnknownName {
            given: name.to_owned(),
            names: T::NAMES,
        })
}

/// Implements [`Named`] (from one table), an inherent `name()`, `Display`,
/// `FromStr` and serde (as unit variants under those names, as a derive with
/// `rename_all` would) for a fieldless enum.
macro_rules! named_enum {
    ($ty:ident { $($variant:ident => $name:literal, $help:literal;)+ }) => {
        impl $crate::names::Named for $ty {
            const TABLE: &'static [(Self, &'static str, &'static str)] =
                &[$(($ty::$variant, $name, $help)),+];
            const NAMES: &'static [&'static str] = &[$($name),+];
        }

        impl $ty {
            /// The value's name (in files, on the command line, in Python).
            #[must_use]
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name,)+
                }
            }
        }

        impl ::core::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::core::str::FromStr for $ty {
            type Err = $crate::names::UnknownName;
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                $crate::names::parse(s)
            }
        }

        impl ::serde::Serialize for $ty {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                let index = <$ty as $crate::names::Named>::TABLE
                    .iter()
                    .position(|(v, _, _)| v == self)
                    .unwrap_or(0);
                s.serialize_unit_variant(
                    stringify!($ty),
                    u32::try_from(index).unwrap_or(0),
                    self.name(),
                )
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $ty {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                d.deserialize_enum(
                    stringify!($ty),
                    <$ty as $crate::names::Named>::NAMES,
                    $crate::names::EnumVisitor::<$ty>::default(),
                )
            }
        }
    };
}
pub(crate) use named_enum;

/// Serde's side of [`named_enum`]: reads a unit variant by name (or index),
/// with serde's own message for an unknown one.
#[doc(hidden)]
pub struct EnumVisitor<T>(core::marker::PhantomData<T>);

impl<T> Default for EnumVisitor<T> {
    fn default() -> Self {
        Self(core::marker::PhantomData)
    }
}

/// The variant identifier, looked up as serde's derive does.
struct VariantSeed<T>(core::marker::PhantomData<T>);

impl<'de, T: Named> serde::de::DeserializeSeed<'de> for VariantSeed<T> {
    type Value = T;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<T, D::Error> {
        d.deserialize_identifier(IdentVisitor(core::marker::PhantomData))
    }
}

struct IdentVisitor<T>(core::marker::PhantomData<T>);

impl<T: Named> serde::de::Visitor<'_> for IdentVisitor<T> {
    type Value = T;
    fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("variant identifier")
    }
    fn visit_u64<E: serde::de::Error>(self, i: u64) -> Result<T, E> {
        usize::try_from(i)
            .ok()
            .and_then(|i| T::TABLE.get(i))
            .map(|&(v, _, _)| v)
            .ok_or_else(|| {
                E::invalid_value(
                    serde::de::Unexpected::Unsigned(i),
                    &format!("variant index 0 <= i < {}", T::TABLE.len()).as_str(),
                )
            })
    }
    fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<T, E> {
        parse(s).map_err(|_| E::unknown_variant(s, T::NAMES))
    }
    fn visit_bytes<E: serde::de::Error>(self, b: &[u8]) -> Result<T, E> {
        match core::str::from_utf8(b) {
            Ok(s) => self.visit_str(s),
            Err(_) => Err(E::unknown_variant(&String::from_utf8_lossy(b), T::NAMES)),
        }
    }
}

impl<'de, T: Named> serde::de::Visitor<'de> for EnumVisitor<T> {
    type Value = T;
    fn expecting(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "one of {}", T::NAMES.join(", "))
    }
    fn visit_enum<A: serde::de::EnumAccess<'de>>(self, data: A) -> Result<T, A::Error> {
        use serde::de::VariantAccess;
        let (value, variant) = data.variant_seed(VariantSeed::<T>(core::marker::PhantomData))?;
        variant.unit_variant()?;
        Ok(value)
    }
}

#[cfg(test)]
mod tests {
    use super::{parse, Named, UnknownName};
    use crate::gaze::Format;
    use crate::model::mode::Mode;
    use crate::model::returns::ModelKind;
    use crate::sim::carla::sampling::Sampling;
    use crate::sim::{Arrival, Detector, Geometry, Variant};

    /// Every name parses back to its value, `Display` and serde write the
    /// name, serde reads it, and names are unique.
    fn round_trips<T>()
    where
        T: Named
            + PartialEq
            + core::fmt::Debug
            + core::fmt::Display
            + core::str::FromStr<Err = UnknownName>
            + serde::Serialize
            + serde::de::DeserializeOwned,
    {
        for &(v, name, help) in T::TABLE {
            assert_eq!(v.to_string(), name);
            assert_eq!(name.parse::<T>(), Ok(v));
            assert_eq!(parse::<T>(name), Ok(v));
            assert_eq!(serde_json::to_string(&v).unwrap(), format!("\"{name}\""));
            assert_eq!(
                serde_json::from_str::<T>(&format!("\"{name}\"")).unwrap(),
                v
            );
            assert!(!help.is_empty() && !help.ends_with('.'), "{name}: {help}");
        }
        let mut names = T::NAMES.to_vec();
        assert_eq!(names.len(), T::TABLE.len());
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), T::TABLE.len(), "names are unique");
        let e = "nope".parse::<T>().unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("'nope' is not one of {}", T::NAMES.join(", "))
        );
        let serde_msg = serde_json::from_str::<T>("\"nope\"")
            .unwrap_err()
            .to_string();
        assert!(
            serde_msg.starts_with("unknown variant `nope`, expected "),
            "{serde_msg}"
        );
    }

    #[test]
    fn every_named_enum_round_trips_through_its_one_table() {
        round_trips::<Mode>();
        round_trips::<ModelKind>();
        round_trips::<Format>();
        round_trips::<Variant>();
        round_trips::<Geometry>();
        round_trips::<Detector>();
        round_trips::<Arrival>();
        round_trips::<Sampling>();
    }

    #[test]
    fn names_are_the_ones_users_type() {
        assert_eq!(Mode::NAMES, ["baseline", "range", "resolution", "joint"]);
        assert_eq!(ModelKind::NAMES, ["argus", "physical"]);
        assert_eq!(Format::NAMES, ["jsonl", "csv", "varjo", "neon"]);
        assert_eq!(
            Variant::NAMES,
            ["baseline", "range", "resolution", "joint", "optimized"]
        );
        assert_eq!(Geometry::NAMES, ["planar", "carla"]);
        assert_eq!(Detector::NAMES, ["first-return", "argus"]);
        assert_eq!(Arrival::NAMES, ["front", "argus-centre"]);
        assert_eq!(Sampling::NAMES, ["carla", "carla-async", "drift"]);
        // serde's message for an unknown name is the derive's, word for word.
        assert_eq!(
            toml::from_str::<std::collections::BTreeMap<String, Mode>>("m = \"x\"")
                .unwrap_err()
                .message(),
            "unknown variant `x`, expected one of `baseline`, `range`, `resolution`, `joint`"
        );
    }
}
