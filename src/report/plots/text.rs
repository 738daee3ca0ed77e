//! Text on the PNG figures, set glyph by glyph on one baseline.
//!
//! plotters 0.3.7 draws `ab_glyph` text with two faults (`style/font/ab_glyph.rs`): each
//! glyph's top is put at `(size / 2 + top) as i32`, which truncates towards one, so a glyph
//! whose top lies above that line (a digit) lands a pixel lower than one whose top lies
//! below it (a full stop) — `0.1` reads `0·1`; and each glyph's bitmap starts at the pen,
//! its left side bearing dropped, so narrow glyphs crowd their neighbours (`r an dom`).
//! [`Typeset`] wraps a backend and draws text itself: every glyph placed at its pen
//! position on the baseline plotters intends (`size / 2` below the text's top), as
//! `ab_glyph` positions it, its bearings kept. Everything else passes
//! through; the layout (sizes, anchors, rotation) is plotters' own, so charts keep their
//! geometry. The SVG figures write `<text>` and are set by their viewer.

use std::sync::OnceLock;

use ab_glyph::{point, Font, FontRef, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// The figures' one font, parsed once.
fn font() -> &'static FontRef<'static> {
    static PARSED: OnceLock<FontRef<'static>> = OnceLock::new();
    PARSED.get_or_init(|| {
        FontRef::try_from_slice(super::FONT).expect("the embedded font was checked at registration")
    })
}

/// The pixels of `text` at `size` px: `(x, y, coverage)` with y down from the text's top,
/// its baseline at `size / 2` (where plotters' layout expects it), whole pixels, each glyph at its pen
/// position with kerning, as plotters measures the text's width.
pub(super) fn glyph_pixels(text: &str, size: f64) -> Vec<(i32, i32, f32)> {
    let font = font().as_scaled(size as f32);
    // A whole pixel, as plotters' `(size / 2) as i32`: on a half pixel every glyph's
    // bottom row would be half inked.
    let baseline = (size / 2.0).floor() as f32;
    let mut pixels = Vec::new();
    let mut pen = 0f32;
    let mut previous = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(previous) = previous {
            pen += font.kern(previous, id);
        }
        previous = Some(id);
        // At a whole pixel too, as plotters puts each glyph: stems stay sharp.
        let glyph = id.with_scale_and_position(font.scale(), point(pen.round(), baseline));
        if let Some(outlined) = font.outline_glyph(glyph) {
            let bounds = outlined.px_bounds();
            let (left, top) = (bounds.min.x as i32, bounds.min.y as i32);
            outlined.draw(|x, y, coverage| {
                pixels.push((left + x as i32, top + y as i32, coverage));
            });
        }
        pen += font.h_advance(id);
    }
    pixels
}

/// A backend whose text is set by [`glyph_pixels`].
pub(super) struct Typeset<B>(pub B);

impl<B: DrawingBackend> DrawingBackend for Typeset<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.0.blit_bitmap(pos, size, src)
    }

    /// As plotters' own `draw_text` (the anchor against its layout box, then the rotation),
    /// with the glyphs from [`glyph_pixels`].
    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let ((min_x, min_y), (max_x, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (width, height) = (max_x - min_x, max_y - min_y);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let turn = style.transform();
        let (w, h) = self.get_size();
        for (x, y, coverage) in glyph_pixels(text, style.size()) {
            let (x, y) = turn.transform(x + dx - min_x, y + dy - min_y);
            let (x, y) = (pos.0 + x, pos.1 + y);
            if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
                let shade = BackendColor {
                    alpha: color.alpha * f64::from(coverage.min(1.0)),
                    rgb: color.rgb,
                };
                self.0.draw_pixel((x, y), shade)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lowest row a glyph inks more than half, in `text` set at `size`, for the glyph
    /// whose pixels lie in columns `columns`.
    fn bottom_row(pixels: &[(i32, i32, f32)], columns: std::ops::Range<i32>) -> i32 {
        pixels
            .iter()
            .filter(|(x, _, c)| columns.contains(x) && *c > 0.5)
            .map(|&(_, y, _)| y)
            .max()
            .expect("inked")
    }

    /// `1.1` at the sizes the figures use: the full stop's lowest inked row is the digit's
    /// (both flat on the baseline), where plotters put it a row higher at some sizes.
    #[test]
    fn a_decimal_point_sits_on_the_baseline() {
        for size in [12.0, 13.0, 14.0, 15.0, 16.0, 18.0, 20.0, 22.0] {
            let font = font().as_scaled(size as f32);
            let advance = |c| font.h_advance(font.glyph_id(c));
            let one = advance('1');
            let stop = advance('.');
            let pixels = glyph_pixels("1.1", size);
            let digit = bottom_row(&pixels, 0..one.floor() as i32);
            let point = bottom_row(&pixels, one.ceil() as i32..(one + stop).floor() as i32);
            assert_eq!(point, digit, "size {size}");
        }
    }

    /// An `i` keeps its left side bearing: its ink starts where the font says, not at
    /// the pen (plotters starts every glyph's bitmap at the pen).
    #[test]
    fn glyphs_keep_their_side_bearings() {
        let font = font().as_scaled(40.0);
        let bearing = font.h_side_bearing(font.glyph_id('i'));
        assert!(bearing > 3.0, "{bearing}");
        let left = glyph_pixels("i", 40.0).iter().map(|p| p.0).min().unwrap();
        assert_eq!(left, bearing.floor() as i32);
    }
}
