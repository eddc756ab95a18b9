//! The functions y = f(x) the keypad offers. The host link takes any expression; the keypad
//! cannot type letters, so it picks one of these, written in the same expression language.

/// The functions y = f(x) the keypad offers (x and y in mm). The host link takes any expression;
/// the keypad cannot type letters, so it picks one of these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum FunctionPreset {
    /// `x^2/20`
    Parabola,
    /// `10*sin(x/5)`
    Wave,
    /// `5*sqrt(x)`, defined for x >= 0.
    Root,
    /// `x^3/400`
    Cubic,
    /// `20*exp(-x^2/200)`
    Bell,
}

impl FunctionPreset {
    /// Every preset, in the order the keypad numbers them (1-based).
    pub const ALL: [FunctionPreset; 5] = [
        FunctionPreset::Parabola,
        FunctionPreset::Wave,
        FunctionPreset::Root,
        FunctionPreset::Cubic,
        FunctionPreset::Bell,
    ];

    /// The expression, in the host link's expression language.
    pub const fn expression(self) -> &'static str {
        match self {
            FunctionPreset::Parabola => "x^2/20",
            FunctionPreset::Wave => "10*sin(x/5)",
            FunctionPreset::Root => "5*sqrt(x)",
            FunctionPreset::Cubic => "x^3/400",
            FunctionPreset::Bell => "20*exp(-x^2/200)",
        }
    }

    /// Position in [`FunctionPreset::ALL`].
    pub fn index(self) -> usize {
        FunctionPreset::ALL.iter().position(|&p| p == self).unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_is_numbered_in_order() {
        for (i, preset) in FunctionPreset::ALL.into_iter().enumerate() {
            assert!(crate::motion::expr::parse(preset.expression()).is_ok(), "{preset:?}");
            assert_eq!(preset.index(), i);
        }
    }
}
