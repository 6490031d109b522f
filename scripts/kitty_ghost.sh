#!/usr/bin/env bash
# The kitty "ghost status line" (issue 22), reproduced without tidepool. Not part of `cargo test`.
#
#   bash scripts/kitty_ghost.sh [OUTDIR]          (default: target/kitty_ghost)
#
# In kitty 0.26 under Xvfb the player's status line sometimes showed faint copies of its
# earlier text, over a background of the wrong colour (docs/terminals/kitty-ghost-before.png).
# This script shows whose it is. A 60-line driver (no tidepool in it) runs inside kitty: it
# places one kitty image over every row but the last (a=T, c=/r= scaling, like the player's)
# and rewrites the last row 30 times a second for 4 s with text of changing length, in the
# player's status colours (38;2;225;232;240 on 48;2;24;38;56) inside synchronized updates, then
# writes a short final text and waits. The screenshot's last row is then read: its background
# colour in a blank cell, and how many pixels right of the final text are not that background
# (text of earlier frames that should have been painted over: the ghost).
#
# Runs: kitty's GL through Mesa's llvmpipe (what LIBGL_ALWAYS_SOFTWARE=1 picks) and softpipe
# (GALLIUM_DRIVER=softpipe), with the image under the text (z=-1, the player's), under the cell
# backgrounds (z=-1073741825), above the text (z=0), without an image, and with the default
# background colour. Measured here (Debian 12, kitty 0.26.5, Mesa 22.3.6; see
# docs/terminals/pictures-at-a-rate.md): ghosts and a wrong background exactly where llvmpipe
# draws an image below the text (kitty's multi-pass "interleaved" drawing), none with softpipe
# or without such an image, synchronized updates or not.
set -u
OUT=${1:-target/kitty_ghost}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
for t in Xvfb kitty import convert; do
  command -v "$t" >/dev/null || { echo "needs $t (apt-get install xvfb kitty imagemagick)"; exit 2; }
done

cat >"$OUT/driver.py" <<'EOF'
# Inside kitty: an image (or none) and a status row rewritten 30 times a second.
import base64, os, sys, time, zlib
z, background, sync = sys.argv[1], sys.argv[2], sys.argv[3] == "sync"
out = sys.stdout.buffer
cols, rows = os.get_terminal_size()
out.write(b"\x1b[?1049h\x1b[?25l\x1b[2J")
if z != "none":
    w, h = 200, 100
    pixels = bytes(v for y in range(h) for x in range(w) for v in ((x * 5) & 255, (y * 7) & 255, 180))
    data = base64.b64encode(zlib.compress(pixels))
    chunks = [data[i:i + 4096] for i in range(0, len(data), 4096)]
    image = b"\x1b[1;1H"
    for i, c in enumerate(chunks):
        more = int(i < len(chunks) - 1)
        if i == 0:
            image += b"\x1b_Ga=T,f=24,s=%d,v=%d,o=z,i=7,q=2,C=1,c=%d,r=%d,z=%s,m=%d;" % (w, h, cols, rows - 1, z.encode(), more)
        else:
            image += b"\x1b_Gm=%d;" % more
        image += c + b"\x1b\\"
    out.write(image)
colours = b"38;2;225;232;240" + (b"" if background == "default" else b";48;2;24;38;56")
def row(text):
    frame = b"\x1b[%d;1H\x1b[%sm" % (rows, colours) + text.ljust(cols)[:cols].encode() + b"\x1b[0m"
    out.write(b"\x1b[?2026h" + frame + b"\x1b[?2026l" if sync else frame)
    out.flush()
start, n = time.monotonic(), 0
while time.monotonic() - start < 4:
    n += 1
    row(" pool - %d fps - %.1f kB/s - %s" % (n % 40, n * 7.3 % 100, "x" * (n % 23)))
    time.sleep(1 / 30)
row(" pool")
time.sleep(60)
EOF

export DISPLAY=${DISPLAY_NUMBER:-:78}
Xvfb "$DISPLAY" -screen 0 1000x700x24 >"$OUT/xvfb.log" 2>&1 &
XVFB=$!
trap 'kill $XVFB 2>/dev/null' EXIT
sleep 2

# The last row of kitty's 960x640 window at its 9x18 cells (see real_terminals.sh): y 617..634.
ROW_Y=617 ROW_H=18
# run DRIVER Z BACKGROUND SYNC
run() {
  local gl=$1 z=$2 bg=$3 sync=$4 name="$1-z$2-$3-$4"
  env LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER="$gl" kitty -o initial_window_width=960 -o initial_window_height=640 \
    -o remember_window_size=no python3 "$OUT/driver.py" "$z" "$bg" "$sync" 2>"$OUT/$name.log" &
  local pid=$!
  sleep 8
  import -window root "$OUT/$name.png"
  kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
  convert "$OUT/$name.png" -crop "960x${ROW_H}+0+${ROW_Y}" +repage "$OUT/$name-row.png"
  # The background: the pixel in the middle of the last cell; the ghost: pixels of columns 8 to
  # 105 (the final text " pool" ends at column 5; the grid ends at x 957, the window's margin
  # follows) that differ from it by more than 24 levels.
  local colour ghost
  colour=$(convert "$OUT/$name-row.png" -format '%[pixel:p{950,9}]' info:)
  ghost=$(convert "$OUT/$name-row.png" -crop "882x${ROW_H}+75+0" +repage \( +clone -fill "$colour" -colorize 100 \) \
    -compose difference -composite -colorspace gray -threshold 9.4% -format '%[fx:round(mean*w*h)]' info:)
  printf '%-10s z %-12s %-8s %-7s background %-22s ghost pixels %s\n' "$gl" "$z" "$bg" "$sync" "$colour" "$ghost" \
    | tee -a "$OUT/summary.txt"
}
: >"$OUT/summary.txt"
for gl in llvmpipe softpipe; do
  run "$gl" -1 status sync
  run "$gl" -1 status nosync
  run "$gl" -1073741825 status sync
  run "$gl" 0 status sync
  run "$gl" none status sync
  run "$gl" -1 default sync
done
convert "$OUT"/llvmpipe-z-1-status-sync-row.png "$OUT"/softpipe-z-1-status-sync-row.png -append "$OUT/rows.png"
echo "screenshots and summary in $OUT (expected background srgb(24,38,56))"
