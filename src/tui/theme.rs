//! Colours, or none: `NO_COLOR` (no-color.org) turns every colour off and the views fall
//! back on symbols and bold/reverse, which read on any terminal.

use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;

use crate::report::plots::palette::hsl_bytes as hsl;
use crate::reuse::MethodKind;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Theme {
    pub color: bool,
}

impl Theme {
    /// Colour unless `NO_COLOR` is set to anything but the empty string.
    pub fn from_env() -> Self {
        let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty());
        Self { color: !no_color }
    }

    pub fn plain() -> Self {
        Self { color: false }
    }

    fn fg(self, color: Color) -> Style {
        if self.color {
            Style::new().fg(color)
        } else {
            Style::new()
        }
    }

    pub fn title(self) -> Style {
        self.fg(Color::Cyan).add_modifier(Modifier::BOLD)
    }

    pub fn dim(self) -> Style {
        if self.color {
            Style::new().fg(Color::DarkGray)
        } else {
            Style::new().add_modifier(Modifier::DIM)
        }
    }

    /// The policy under the cursor.
    pub fn cursor(self) -> Style {
        Style::new().add_modifier(Modifier::REVERSED)
    }

    /// The policy acting now, or the call being made.
    pub fn active(self) -> Style {
        self.fg(Color::Green).add_modifier(Modifier::BOLD)
    }

    /// Edges that just carried activation.
    pub fn spreading(self) -> Style {
        self.fg(Color::Yellow).add_modifier(Modifier::BOLD)
    }

    pub fn stopped(self) -> Style {
        self.fg(Color::Red)
    }

    /// A curve's colour: SAP-Net red, then the paper's blue, orange and green.
    pub fn series(self, i: usize) -> Style {
        const COLORS: [Color; 4] = [
            Color::Red,
            Color::Blue,
            Color::Rgb(255, 127, 14),
            Color::Green,
        ];
        self.fg(COLORS[i % COLORS.len()])
    }

    /// How a curve is drawn, and the symbol its legend entry starts with: braille in
    /// colour (the colours tell curves apart), else a marker of its own per curve.
    pub fn series_marker(self, i: usize) -> (Marker, &'static str) {
        const MARKERS: [(Marker, &str); 3] = [
            (Marker::Dot, "• "),
            (Marker::Block, "█ "),
            (Marker::Bar, "▄ "),
        ];
        if self.color {
            (Marker::Braille, "")
        } else {
            MARKERS[i % MARKERS.len()]
        }
    }

    /// A method's colour: its family's hue (`MethodKind::hue`, as the plots draw it),
    /// the `member`-th method of a family a shade lighter or darker so that variants
    /// read apart; a family without saturation (the DQN baselines) in greys.
    pub fn method(self, kind: MethodKind, member: usize) -> Style {
        const SHADES: [f64; 3] = [0.55, 0.40, 0.70];
        let lightness = SHADES[member % SHADES.len()];
        let (r, g, b) = hsl(
            f64::from(kind.hue),
            f64::from(kind.saturation) / 100.0,
            lightness,
        );
        self.fg(Color::Rgb(r, g, b))
    }

    /// A node's colour by its share `level` (0 to 1) of the highest activation: cold blue
    /// to hot red.
    pub fn heat(self, level: f64) -> Style {
        let level = if level.is_finite() {
            level.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if !self.color {
            return if level > 0.5 {
                Style::new().add_modifier(Modifier::BOLD)
            } else {
                Style::new()
            };
        }
        let red = (70.0 + 185.0 * level) as u8;
        let blue = (230.0 - 180.0 * level) as u8;
        Style::new().fg(Color::Rgb(red, 90, blue))
    }
}

/// A node's symbol by its share of the highest activation, for reading without colour.
pub fn heat_symbol(level: f64) -> &'static str {
    match level {
        l if l >= 0.75 => "●",
        l if l >= 0.25 => "◐",
        _ => "○",
    }
}

#[cfg(test)]
mod tests {
    use super::hsl;

    #[test]
    fn hsl_by_hand() {
        assert_eq!(hsl(0.0, 1.0, 0.5), (255, 0, 0));
        assert_eq!(hsl(120.0, 1.0, 0.5), (0, 255, 0));
        assert_eq!(hsl(240.0, 1.0, 0.25), (0, 0, 128));
        assert_eq!(
            hsl(200.0, 0.0, 0.4),
            (102, 102, 102),
            "no saturation: a grey"
        );
    }
}
