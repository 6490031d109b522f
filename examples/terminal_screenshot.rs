//! Paints captured terminal output (e.g. `tmux capture-pane -e -N -p`) as a PNG, the way a
//! terminal with 8x16-pixel cells shows it: half blocks as two coloured halves, text in an 8x8
//! bitmap font. The gallery's player screenshot is made with it (see scripts/gallery.sh).
//!
//! Usage: `cargo run --release --example terminal_screenshot CAPTURE.ans OUT.png COLS ROWS`

use font8x8::UnicodeFonts;
use tidepool::testing::TerminalModel;
use tiny_skia::{Pixmap, PremultipliedColorU8};

const CELL_W: u32 = 8;
const CELL_H: u32 = 16;
const DEFAULT_FG: [u8; 3] = [220, 220, 220];
const DEFAULT_BG: [u8; 3] = [12, 12, 16];

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, capture, out, cols, rows] = args.as_slice() else {
        eprintln!("usage: terminal_screenshot CAPTURE.ans OUT.png COLS ROWS");
        std::process::exit(2);
    };
    let (cols, rows): (usize, usize) = (cols.parse().expect("COLS"), rows.parse().expect("ROWS"));
    let bytes = std::fs::read(capture).expect("a readable capture");
    // One spare row: the capture's last newline must not scroll the first row away.
    let mut screen = TerminalModel::new(cols, rows + 1);
    screen.feed(&bytes);
    let mut pixmap = Pixmap::new(cols as u32 * CELL_W, rows as u32 * CELL_H).expect("a picture");
    let width = pixmap.width();
    let pixels = pixmap.pixels_mut();
    let mut put = |x: u32, y: u32, [r, g, b]: [u8; 3]| {
        pixels[(y * width + x) as usize] = PremultipliedColorU8::from_rgba(r, g, b, 255).expect("opaque");
    };
    for row in 0..rows {
        for col in 0..cols {
            let cell = screen.cell(col, row);
            let (fg, bg) = (cell.fg.unwrap_or(DEFAULT_FG), cell.bg.unwrap_or(DEFAULT_BG));
            let (x0, y0) = (col as u32 * CELL_W, row as u32 * CELL_H);
            let glyph = match cell.ch {
                '\u{2580}' | '\u{2584}' | '\u{2588}' | ' ' => None,
                ch => Some(font8x8::BASIC_FONTS.get(ch).or_else(|| font8x8::LATIN_FONTS.get(ch)).unwrap_or([0; 8])),
            };
            for dy in 0..CELL_H {
                for dx in 0..CELL_W {
                    let upper = dy < CELL_H / 2;
                    let colour = match cell.ch {
                        '\u{2580}' => {
                            if upper {
                                fg
                            } else {
                                bg
                            }
                        }
                        '\u{2584}' => {
                            if upper {
                                bg
                            } else {
                                fg
                            }
                        }
                        '\u{2588}' => fg,
                        _ => match glyph {
                            Some(g) if (g[(dy / 2) as usize] >> dx) & 1 == 1 => fg,
                            _ => bg,
                        },
                    };
                    put(x0 + dx, y0 + dy, colour);
                }
            }
        }
    }
    std::fs::write(out, tidepool::encode::png(&pixmap)).expect("a writable output");
    println!("{out}: {cols}x{rows} cells");
}
