//! The one font every picture uses: DejaVu Sans, embedded, so that PNGs
//! and SVGs have their text on a machine without fonts.

use std::sync::Once;

use plotters::style::{register_font, FontStyle};

/// Registers the embedded DejaVu Sans as plotters' `sans-serif` (once per
/// process; later calls do nothing).
pub(crate) fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // An embedded TTF always registers; were it to fail, pictures would
        // lack their text but still show their data.
        let _ = register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}
