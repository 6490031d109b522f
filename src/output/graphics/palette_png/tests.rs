use super::*;
use crate::output::graphics::lossy_png;
use crate::output::graphics::test_pictures::golden_pool;

/// The golden pool cut to `width` columns (an odd width leaves the last byte of a packed row
/// partly filled).
fn pool(width: u32) -> (u32, u32, Vec<u8>) {
    let (w, h, rgb) = golden_pool();
    let cut = rgb.chunks_exact(w as usize * 3).flat_map(|row| &row[..width as usize * 3]).copied().collect();
    (width, h, cut)
}

fn luma_rms(a: &[u8], b: &[u8]) -> f64 {
    let luma = |p: &[u8]| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]);
    let sum: f64 = a.chunks_exact(3).zip(b.chunks_exact(3)).map(|(x, y)| (luma(x) - luma(y)).powi(2)).sum();
    (sum / (a.len() / 3) as f64).sqrt()
}

#[test]
fn decoders_read_exactly_the_rewritten_pixels_at_every_bit_depth() {
    // 2, 4, 16 and 256 colours: 1, 2, 4 and 8 bits a pixel; 17 colours take 8 bits.
    let (w, h, rgb) = pool(637);
    let mut errors = Vec::new();
    for (colours, bits) in [(2u16, 1u8), (4, 2), (16, 4), (17, 8), (256, 8)] {
        let (mut shown, mut png) = (rgb.clone(), Vec::new());
        encode(&mut shown, w, h, colours, &mut png);
        assert_eq!((png[24], png[25]), (bits, 3), "{colours} colours: bit depth and colour type");
        let decoded = image::load_from_memory(&png).unwrap().to_rgb8().into_raw();
        assert!(decoded == shown, "{colours} colours: the decoder shows the rewritten pixels");
        let mut used: Vec<&[u8]> = shown.chunks_exact(3).collect();
        used.sort_unstable();
        used.dedup();
        assert!(used.len() <= usize::from(colours), "{colours} colours: {} shown", used.len());
        errors.push(luma_rms(&shown, &rgb));
    }
    assert!(errors.windows(2).all(|e| e[1] <= e[0]), "more colours, less error: {errors:?}");
    assert!(errors[4] < 1.5, "256 colours stay near the picture: {errors:?}");
}

#[test]
fn sixteen_colours_cost_fewer_bytes_than_the_lossy_png() {
    // What the palette is for: kitty's bytes a picture under a rate (the golden pool: 0.20
    // against 0.27 bytes a pixel, luma error 3.8 against 3.7).
    let (w, h, rgb) = golden_pool();
    let (mut lossy, mut lossy_png) = (rgb.clone(), Vec::new());
    lossy_png::encode(&mut lossy, w, h, 24, &mut lossy_png);
    let (mut shown, mut png) = (rgb.clone(), Vec::new());
    encode(&mut shown, w, h, 16, &mut png);
    assert!(png.len() * 5 < lossy_png.len() * 4, "{} against {} bytes", png.len(), lossy_png.len());
    let (error, lossy_error) = (luma_rms(&shown, &rgb), luma_rms(&lossy, &rgb));
    assert!(error < lossy_error * 1.2, "luma error {error} against {lossy_error}");
}

#[test]
fn the_palette_is_kept_until_the_colours_drift_or_another_count_is_asked() {
    let (w, h, rgb) = golden_pool();
    let palette = |png: &[u8]| {
        let at = png.windows(4).position(|c| c == b"PLTE").unwrap();
        let len = u32::from_be_bytes(png[at - 4..at].try_into().unwrap()) as usize;
        png[at + 4..at + 4 + len].to_vec()
    };
    let mut kept = Encoder::default();
    let (mut first, mut png) = (rgb.clone(), Vec::new());
    kept.encode(&mut first, w, h, 16, &mut png);
    let fitted = palette(&png);
    // The picture a little brighter: the same palette (no refit for a small drift).
    let brighter: Vec<u8> = rgb.iter().map(|v| v.saturating_add(1)).collect();
    kept.encode(&mut brighter.clone(), w, h, 16, &mut png);
    assert_eq!(palette(&png), fitted, "a small drift keeps the palette");
    // Far brighter: refitted, so the picture stays near its colours.
    let far: Vec<u8> = rgb.iter().map(|v| v.saturating_add(60)).collect();
    let mut shown = far.clone();
    kept.encode(&mut shown, w, h, 16, &mut png);
    assert_ne!(palette(&png), fitted, "a drift refits");
    let (mut fresh, mut fresh_png) = (far.clone(), Vec::new());
    encode(&mut fresh, w, h, 16, &mut fresh_png);
    assert!(png == fresh_png && shown == fresh, "a refit is a new encoder's fit");
    // Another number of colours: refitted at once.
    kept.encode(&mut far.clone(), w, h, 4, &mut png);
    assert_eq!(palette(&png).len(), 4 * 3, "four colours asked, four given");
}
