//! One pattern for the enums a user picks by name (debug views, shadow modes,
//! interpolation, rasterizer methods): `named_enum!` writes each choice's name
//! once, beside its variant, and the command line, listings, menus and saved
//! settings all use that name.

use serde::de::{self, Deserializer, EnumAccess, VariantAccess, Visitor};
use serde::Serializer;
use std::fmt;
use std::marker::PhantomData;

/// An enum whose choices have names (implemented by `named_enum!`).
pub trait Named: Copy + PartialEq + 'static {
    /// What one choice is, for messages: "view", "shadow mode".
    const KIND: &'static str;
    /// Every choice, in the order listings and menus show them.
    const CHOICES: &'static [Self];
    /// The name the command line, listings and saved settings use.
    fn name(self) -> &'static str;
    /// Earlier spellings, still accepted when reading saved settings.
    fn former_names(self) -> &'static [&'static str];
}

/// The choice called `s`; the error names the kind and lists the choices.
pub fn parse<T: Named>(s: &str) -> Result<T, String> {
    T::CHOICES.iter().copied().find(|c| c.name() == s).ok_or_else(|| {
        let names: Vec<_> = T::CHOICES.iter().map(|c| c.name()).collect();
        format!("unknown {} \"{s}\" (choose from {})", T::KIND, names.join(", "))
    })
}

/// As `parse`, also accepting a former name (saved data may predate a rename).
pub fn parse_saved<T: Named>(s: &str) -> Result<T, String> {
    parse(s).or_else(|e| T::CHOICES.iter().copied().find(|c| c.former_names().contains(&s)).ok_or(e))
}

/// Serializes a choice as the unit variant called by its name (a string in
/// JSON, an identifier in RON).
pub fn serialize<T: Named, S: Serializer>(value: T, type_name: &'static str, serializer: S) -> Result<S::Ok, S::Error> {
    let index = T::CHOICES.iter().position(|c| *c == value).unwrap_or(0) as u32;
    serializer.serialize_unit_variant(type_name, index, value.name())
}

/// Reads a choice by its name or a former name, as a unit variant (RON
/// identifiers) or a plain string.
pub fn deserialize<'de, T: Named, D: Deserializer<'de>>(type_name: &'static str, names: &'static [&'static str], deserializer: D) -> Result<T, D::Error> {
    deserializer.deserialize_enum(type_name, names, NameVisitor(PhantomData))
}

struct NameVisitor<T>(PhantomData<T>);

impl<'de, T: Named> Visitor<'de> for NameVisitor<T> {
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a {} name", T::KIND)
    }

    fn visit_str<E: de::Error>(self, s: &str) -> Result<T, E> {
        parse_saved(s).map_err(E::custom)
    }

    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<T, A::Error> {
        let (VariantName(name), variant) = data.variant()?;
        variant.unit_variant()?;
        parse_saved(&name).map_err(de::Error::custom)
    }
}

/// A variant's name, read as an identifier (how formats name enum variants).
struct VariantName(String);

impl<'de> serde::Deserialize<'de> for VariantName {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct NameString;
        impl Visitor<'_> for NameString {
            type Value = String;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a variant name")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<String, E> {
                Ok(s.to_string())
            }
        }
        deserializer.deserialize_identifier(NameString).map(VariantName)
    }
}

/// Declares an enum whose choices have names: each variant is followed by
/// `= "name"` and optionally `| "former-name"`s. Generates the enum, `ALL`,
/// `name`, `parse` (error: `unknown KIND "s" (choose from ...)`), `Named`,
/// and serde by name (former names accepted when reading).
macro_rules! named_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $Name:ident ($kind:literal) {
            $( $(#[$variant_meta:meta])* $Variant:ident = $name:literal $(| $former:literal)* ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $Name {
            $( $(#[$variant_meta])* $Variant ),+
        }

        impl $Name {
            /// Every choice, in the order listings and menus show them.
            pub const ALL: [$Name; [$($name),+].len()] = [$($Name::$Variant),+];

            /// The name the command line, listings and saved settings use.
            pub fn name(self) -> &'static str {
                match self {
                    $( $Name::$Variant => $name ),+
                }
            }

            /// The choice called `s`; the error lists the choices.
            pub fn parse(s: &str) -> Result<$Name, String> {
                $crate::named::parse(s)
            }
        }

        impl $crate::named::Named for $Name {
            const KIND: &'static str = $kind;
            const CHOICES: &'static [$Name] = &$Name::ALL;

            fn name(self) -> &'static str {
                $Name::name(self)
            }

            fn former_names(self) -> &'static [&'static str] {
                match self {
                    $( $Name::$Variant => &[$($former),*] ),+
                }
            }
        }

        impl ::serde::Serialize for $Name {
            fn serialize<S: ::serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                $crate::named::serialize(*self, stringify!($Name), serializer)
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $Name {
            fn deserialize<D: ::serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                $crate::named::deserialize(stringify!($Name), &[$($name),+], deserializer)
            }
        }
    };
}

pub(crate) use named_enum;

#[cfg(test)]
mod tests {
    use super::*;

    named_enum! {
        /// Test choices.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        enum Fruit ("fruit") {
            Apple = "apple",
            /// Renamed: the old spelling still reads.
            BloodOrange = "blood-orange" | "bloodorange",
        }
    }

    #[test]
    fn names_parse_and_errors_by_hand() {
        assert_eq!(Fruit::ALL, [Fruit::Apple, Fruit::BloodOrange]);
        assert_eq!(Fruit::BloodOrange.name(), "blood-orange");
        assert_eq!(Fruit::parse("blood-orange"), Ok(Fruit::BloodOrange));
        assert_eq!(Fruit::parse("pear"), Err("unknown fruit \"pear\" (choose from apple, blood-orange)".to_string()));
        // The command line takes current names only; saved data former ones too.
        assert!(Fruit::parse("bloodorange").is_err());
        assert_eq!(parse_saved::<Fruit>("bloodorange"), Ok(Fruit::BloodOrange));
    }

    #[test]
    fn serde_uses_the_names_and_reads_former_ones() {
        assert_eq!(serde_json::to_string(&Fruit::BloodOrange).unwrap(), "\"blood-orange\"");
        assert_eq!(serde_json::from_str::<Fruit>("\"blood-orange\"").unwrap(), Fruit::BloodOrange);
        assert_eq!(serde_json::from_str::<Fruit>("\"bloodorange\"").unwrap(), Fruit::BloodOrange);
        let e = serde_json::from_str::<Fruit>("\"pear\"").unwrap_err().to_string();
        assert!(e.contains("unknown fruit \"pear\""), "{e}");
    }
}
