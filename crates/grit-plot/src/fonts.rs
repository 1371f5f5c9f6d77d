//! The embedded font. plotters' `ab_glyph` backend draws only fonts registered by name, and
//! the feature is shared by every plotters user in the binary (the SVG charts of
//! `grit verify` too), so the binary registers them once at start-up.

use plotters::style::{register_font, FontStyle};

/// Registers DejaVu Sans for plotters' `sans-serif`, `serif` and `monospace` families;
/// idempotent, and needed before any plotters chart draws text.
pub fn register_fonts() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let faces = [
            (FontStyle::Normal, dejavu::sans::regular()),
            (FontStyle::Bold, dejavu::sans::bold()),
            (FontStyle::Italic, dejavu::sans::oblique()),
            (FontStyle::Oblique, dejavu::sans::oblique()),
        ];
        for family in ["sans-serif", "serif"] {
            for (style, bytes) in faces {
                // The bytes are the crate's own TTF files, which parse; a failure would
                // show as a chart error naming the missing font.
                let _ = register_font(family, style, bytes);
            }
        }
        let _ = register_font("monospace", FontStyle::Normal, dejavu::sans_mono::regular());
    });
}

#[cfg(test)]
mod tests {
    use plotters::prelude::*;

    #[test]
    fn text_draws_with_the_embedded_font() {
        super::register_fonts();
        let mut buf = vec![255u8; 200 * 60 * 3];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (200, 60)).into_drawing_area();
            root.draw_text(
                "Erosion 45°",
                &TextStyle::from(("sans-serif", 30).into_font()).color(&BLACK),
                (5, 10),
            )
            .unwrap();
            root.present().unwrap();
        }
        assert!(
            buf.iter().any(|&b| b < 128),
            "no dark pixel: text not drawn"
        );
    }
}
