//! How the parts of the fit options read the config's `[fit]` and `[fit.options]` keys.

use serde::de::MapAccess;

/// A part of the options that reads keys of the config's `[fit]` and `[fit.options]`
/// tables: which keys in each, and how the value of one is read (serde deserializes it to
/// its field's type). Written by `option_keys!`, one `"key" => field`
/// pair per key.
pub trait OptionKeys {
    /// Its keys in `[fit]`.
    const FIT_KEYS: &'static [&'static str];
    /// Its keys in `[fit.options]`.
    const OPTIONS_KEYS: &'static [&'static str];
    /// Reads the value of `key` from `map` when `key` is one of its keys (`Ok(false)`
    /// otherwise, with nothing read).
    fn read_key<'de, A: MapAccess<'de>>(
        &mut self,
        key: &str,
        map: &mut A,
    ) -> Result<bool, A::Error>;
}

/// Implements [`OptionKeys`] for a part: `fit: ["key" => field, ...]` are its `[fit]` keys,
/// `options: [...]` its `[fit.options]` keys, each read into its field.
macro_rules! option_keys {
    ($part:ty {
        fit: [$($fit_key:literal => $fit_field:ident),* $(,)?],
        options: [$($key:literal => $field:ident),* $(,)?] $(,)?
    }) => {
        impl $crate::identify::values::option_keys::OptionKeys for $part {
            const FIT_KEYS: &'static [&'static str] = &[$($fit_key),*];
            const OPTIONS_KEYS: &'static [&'static str] = &[$($key),*];
            fn read_key<'de, A: serde::de::MapAccess<'de>>(
                &mut self,
                key: &str,
                map: &mut A,
            ) -> Result<bool, A::Error> {
                match key {
                    $($fit_key => self.$fit_field = map.next_value()?,)*
                    $($key => self.$field = map.next_value()?,)*
                    _ => return Ok(false),
                }
                Ok(true)
            }
        }
    };
}
pub(crate) use option_keys;
