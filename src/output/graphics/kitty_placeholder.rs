//! kitty's Unicode placeholders: the image drawn through ordinary text, so that a program that
//! knows nothing about graphics (tmux) moves and clips it with its pane.
//!
//! Each cell of the image is `U+10EEEE` followed by two combining marks, the first naming the
//! row and the second the column; the foreground colour carries the image id (24-bit colour,
//! so ids below 2^24 need no third mark). The image itself is sent with `U=1` (a virtual
//! placement, see [`crate::output::graphics::kitty`]). The text only needs printing when the
//! area changes: re-sending the image data re-creates the virtual placement and the same
//! placeholder cells show the new picture.

/// The placeholder character.
pub const PLACEHOLDER: char = '\u{10EEEE}';

/// The combining marks that number rows and columns: entry `n` means `n`. These are the code
/// points of the kitty protocol's `rowcolumn-diacritics.txt`, in its order (Unicode combining
/// marks of class 230).
pub const DIACRITICS: [u32; 297] = [
    0x0305, 0x030D, 0x030E, 0x0310, 0x0312, 0x033D, 0x033E, 0x033F, 0x0346, 0x034A, 0x034B, 0x034C, 0x0350, 0x0351,
    0x0352, 0x0357, 0x035B, 0x0363, 0x0364, 0x0365, 0x0366, 0x0367, 0x0368, 0x0369, 0x036A, 0x036B, 0x036C, 0x036D,
    0x036E, 0x036F, 0x0483, 0x0484, 0x0485, 0x0486, 0x0487, 0x0592, 0x0593, 0x0594, 0x0595, 0x0597, 0x0598, 0x0599,
    0x059C, 0x059D, 0x059E, 0x059F, 0x05A0, 0x05A1, 0x05A8, 0x05A9, 0x05AB, 0x05AC, 0x05AF, 0x05C4, 0x0610, 0x0611,
    0x0612, 0x0613, 0x0614, 0x0615, 0x0616, 0x0617, 0x0657, 0x0658, 0x0659, 0x065A, 0x065B, 0x065D, 0x065E, 0x06D6,
    0x06D7, 0x06D8, 0x06D9, 0x06DA, 0x06DB, 0x06DC, 0x06DF, 0x06E0, 0x06E1, 0x06E2, 0x06E4, 0x06E7, 0x06E8, 0x06EB,
    0x06EC, 0x0730, 0x0732, 0x0733, 0x0735, 0x0736, 0x073A, 0x073D, 0x073F, 0x0740, 0x0741, 0x0743, 0x0745, 0x0747,
    0x0749, 0x074A, 0x07EB, 0x07EC, 0x07ED, 0x07EE, 0x07EF, 0x07F0, 0x07F1, 0x07F3, 0x0816, 0x0817, 0x0818, 0x0819,
    0x081B, 0x081C, 0x081D, 0x081E, 0x081F, 0x0820, 0x0821, 0x0822, 0x0823, 0x0825, 0x0826, 0x0827, 0x0829, 0x082A,
    0x082B, 0x082C, 0x082D, 0x0951, 0x0953, 0x0954, 0x0F82, 0x0F83, 0x0F86, 0x0F87, 0x135D, 0x135E, 0x135F, 0x17DD,
    0x193A, 0x1A17, 0x1A75, 0x1A76, 0x1A77, 0x1A78, 0x1A79, 0x1A7A, 0x1A7B, 0x1A7C, 0x1B6B, 0x1B6D, 0x1B6E, 0x1B6F,
    0x1B70, 0x1B71, 0x1B72, 0x1B73, 0x1CD0, 0x1CD1, 0x1CD2, 0x1CDA, 0x1CDB, 0x1CE0, 0x1DC0, 0x1DC1, 0x1DC3, 0x1DC4,
    0x1DC5, 0x1DC6, 0x1DC7, 0x1DC8, 0x1DC9, 0x1DCB, 0x1DCC, 0x1DD1, 0x1DD2, 0x1DD3, 0x1DD4, 0x1DD5, 0x1DD6, 0x1DD7,
    0x1DD8, 0x1DD9, 0x1DDA, 0x1DDB, 0x1DDC, 0x1DDD, 0x1DDE, 0x1DDF, 0x1DE0, 0x1DE1, 0x1DE2, 0x1DE3, 0x1DE4, 0x1DE5,
    0x1DE6, 0x1DFE, 0x20D0, 0x20D1, 0x20D4, 0x20D5, 0x20D6, 0x20D7, 0x20DB, 0x20DC, 0x20E1, 0x20E7, 0x20E9, 0x20F0,
    0x2CEF, 0x2CF0, 0x2CF1, 0x2DE0, 0x2DE1, 0x2DE2, 0x2DE3, 0x2DE4, 0x2DE5, 0x2DE6, 0x2DE7, 0x2DE8, 0x2DE9, 0x2DEA,
    0x2DEB, 0x2DEC, 0x2DED, 0x2DEE, 0x2DEF, 0x2DF0, 0x2DF1, 0x2DF2, 0x2DF3, 0x2DF4, 0x2DF5, 0x2DF6, 0x2DF7, 0x2DF8,
    0x2DF9, 0x2DFA, 0x2DFB, 0x2DFC, 0x2DFD, 0x2DFE, 0x2DFF, 0xA66F, 0xA67C, 0xA67D, 0xA6F0, 0xA6F1, 0xA8E0, 0xA8E1,
    0xA8E2, 0xA8E3, 0xA8E4, 0xA8E5, 0xA8E6, 0xA8E7, 0xA8E8, 0xA8E9, 0xA8EA, 0xA8EB, 0xA8EC, 0xA8ED, 0xA8EE, 0xA8EF,
    0xA8F0, 0xA8F1, 0xAAB0, 0xAAB2, 0xAAB3, 0xAAB7, 0xAAB8, 0xAABE, 0xAABF, 0xAAC1, 0xFE20, 0xFE21, 0xFE22, 0xFE23,
    0xFE24, 0xFE25, 0xFE26, 0x10A0F, 0x10A38, 0x1D185, 0x1D186, 0x1D187, 0x1D188, 0x1D189, 0x1D1AA, 0x1D1AB, 0x1D1AC,
    0x1D1AD, 0x1D242, 0x1D243, 0x1D244,
];

/// The most rows or columns a placeholder area can have (one mark per number).
pub const MAX_CELLS: u16 = DIACRITICS.len() as u16;

/// The largest image id the placeholders carry in their foreground colour alone.
pub const MAX_IMAGE_ID: u32 = 0x00FF_FFFF;

fn diacritic(n: u16) -> char {
    char::from_u32(DIACRITICS[usize::from(n)]).expect("the table holds valid code points")
}

/// Appends the placeholder text for image `image_id` over `cols x rows` cells whose top-left
/// cell is (`col`, `row`), 0-based; areas are clipped to 297 cells a side. The cursor is left
/// after the last cell and the foreground colour reset. Every cell carries both marks, so no
/// terminal has to guess a position from its neighbour.
pub fn push_placeholders(out: &mut Vec<u8>, image_id: u32, col: u16, row: u16, cols: u16, rows: u16) {
    debug_assert!(image_id <= MAX_IMAGE_ID, "placeholder ids are 24-bit");
    let [_, r, g, b] = image_id.to_be_bytes();
    let mut buf = [0u8; 4];
    for y in 0..rows.min(MAX_CELLS) {
        out.extend_from_slice(
            format!("\x1b[{};{}H\x1b[38;2;{r};{g};{b}m", u32::from(row) + u32::from(y) + 1, u32::from(col) + 1)
                .as_bytes(),
        );
        for x in 0..cols.min(MAX_CELLS) {
            for ch in [PLACEHOLDER, diacritic(y), diacritic(x)] {
                out.extend_from_slice(ch.encode_utf8(&mut buf).as_bytes());
            }
        }
        out.extend_from_slice(b"\x1b[39m");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_protocols_example_cells() {
        // The protocol's own example: image 42, row 1 column 0 is U+10EEEE U+030D U+0305.
        let mut out = Vec::new();
        push_placeholders(&mut out, 42, 0, 0, 2, 2);
        let text = String::from_utf8(out).unwrap();
        assert!(
            text.starts_with("\x1b[1;1H\x1b[38;2;0;0;42m\u{10EEEE}\u{305}\u{305}\u{10EEEE}\u{305}\u{30D}\x1b[39m"),
            "{text:?}"
        );
        assert!(
            text.ends_with("\x1b[2;1H\x1b[38;2;0;0;42m\u{10EEEE}\u{30D}\u{305}\u{10EEEE}\u{30D}\u{30D}\x1b[39m"),
            "{text:?}"
        );
    }

    #[test]
    fn ids_go_in_the_foreground_colour_and_the_origin_is_respected() {
        let mut out = Vec::new();
        push_placeholders(&mut out, 0x01_02_03, 4, 6, 1, 1);
        assert_eq!(String::from_utf8(out).unwrap(), "\x1b[7;5H\x1b[38;2;1;2;3m\u{10EEEE}\u{305}\u{305}\x1b[39m");
    }

    #[test]
    fn diacritics_are_distinct_combining_marks() {
        let set: std::collections::BTreeSet<u32> = DIACRITICS.iter().copied().collect();
        assert_eq!(set.len(), DIACRITICS.len());
        assert!(DIACRITICS.iter().all(|&c| char::from_u32(c).is_some()));
    }
}
