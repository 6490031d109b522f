#!/usr/bin/env bash
# Real terminals for issue 15 (kitty graphics, sixel), under Xvfb. Not part of `cargo test`.
#
#   bash scripts/real_terminals.sh [OUTDIR]      (default: target/real_terminals)
#
# Installs Debian's xvfb, kitty, xterm, imagemagick, xdotool and tmux (as root, when missing),
# starts Xvfb, and runs `examples/graphics_demo.rs` (the detection and the encoders, before the
# player is wired) in:
#   - kitty (LIBGL_ALWAYS_SOFTWARE=1), local: kitty protocol through temporary files;
#   - kitty with SSH_TTY set: the direct (zlib + base64) transmission an SSH session gets;
#   - xterm -ti vt340 with 256 colour registers: sixel;
#   - tmux inside kitty with allow-passthrough on and off, and tmux inside xterm.
# Each run probes, draws the pool's golden picture over every row but the last, then paints a
# red square and sends only that change; the screenshot (`import -window root`) is taken after
# the change. The picture's region of the screenshot is compared with the picture the demo meant
# to show (REPORT.png: the picture, for sixel its dithered version; scaled to the region the
# terminal drew it in when the terminal scales) by ImageMagick's normalized RMSE. kitty and sixel
# pass at RMSE <= $EXACT (they are pixel-exact when the picture is not scaled: measured 0);
# half-block cells at <= $TOLERANCE (two pixels a cell against the full picture: measured
# 0.04-0.07; a missing or misplaced picture measures > 0.2).
#
# Then the player itself: `tidepool play --graphics auto` in kitty, in xterm, and inside tmux in
# each (see `run_player` below): keys through xdotool (space, then `p` to pause and `s` for the
# player's own screenshot), a screenshot of the screen, and the picture's region compared with
# the player's PNG, scaled to the region (the scene renders within 480x300 and the terminal,
# or for sixel the player, scales it up, so nothing here is pixel for pixel). A run passes at
# normalized RMSE <= $PLAYER_TOLERANCE (a missing or misplaced picture measures > 0.2).
# PLAYER_ONLY=1 skips the demo runs.
set -u
OUT=${1:-target/real_terminals}
TOLERANCE=${TOLERANCE:-0.08}
EXACT=${EXACT:-0.01}
PLAYER_TOLERANCE=${PLAYER_TOLERANCE:-0.12}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

need=()
for t in Xvfb:xvfb kitty:kitty xterm:xterm import:imagemagick xdotool:xdotool tmux:tmux; do
  command -v "${t%%:*}" >/dev/null || need+=("${t#*:}")
done
if [ ${#need[@]} -gt 0 ]; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}" \
    || { echo "cannot install ${need[*]}"; exit 2; }
fi

if [ -z "${PLAYER_ONLY:-}" ]; then cargo build --example graphics_demo || exit 2; fi
cargo build --release || exit 2
TIDEPOOL=$(pwd)/target/release/tidepool
# How long each demo shows its picture, in seconds.
SECONDS_SHOWN=10
# The player waits 150 ms for the terminal's answers. Terminals started under Xvfb with
# software OpenGL on a shared machine answer their first query late (kitty took 150-160 ms at
# its window's start here, 20-60 ms after), so the demo waits longer; each report records how
# long the answers really took ("probe took").
export GRAPHICS_DEMO_BUDGET_MS=${GRAPHICS_DEMO_BUDGET_MS:-1000}
DEMO=$(pwd)/target/debug/examples/graphics_demo

export DISPLAY=${DISPLAY_NUMBER:-:77}
Xvfb "$DISPLAY" -screen 0 1600x1000x24 >"$OUT/xvfb.log" 2>&1 &
XVFB=$!
trap 'kill $XVFB 2>/dev/null' EXIT
sleep 2

cat >"$OUT/tmux-on.conf" <<'EOF'
set -g allow-passthrough on
set -g status off
EOF
cat >"$OUT/tmux-off.conf" <<'EOF'
set -g allow-passthrough off
set -g status off
EOF

KITTY=(env LIBGL_ALWAYS_SOFTWARE=1 kitty -o initial_window_width=960 -o initial_window_height=640
  -o remember_window_size=no)
XTERM=(xterm -ti vt340 -xrm 'XTerm*numColorRegisters: 256' -xrm 'XTerm*maxGraphicSize: 2000x2000'
  -geometry 120x40+0+0)

# run NAME TERMINAL-COMMAND... -- COMMAND-INSIDE...
run() {
  local name=$1; shift
  local report="$OUT/$name.txt"
  rm -f "$report" "$report.png"
  "$@" &
  local pid=$!
  # The demo draws at once, changes the picture after SECONDS/2 and ends after SECONDS: the
  # screenshot is taken between the change and the end.
  sleep "$SECONDS_SHOWN"
  import -window root "$OUT/$name-screen.png"
  wait $pid 2>/dev/null
  if [ ! -f "$report" ]; then
    printf '%-16s no report (the demo did not run)\n' "$name" | tee -a "$OUT/summary.txt"
    return
  fi
  local mode cw ch sw sh
  mode=$(sed -n 's/^ *mode: \([A-Za-z0-9]*\),$/\1/p' "$report" | tail -1)
  read -r sw sh < <(awk '/shown_px/{getline a; getline b; gsub(/[ ,]/,"",a); gsub(/[ ,]/,"",b); print a, b}' "$report")
  read -r cw ch < <(awk '/cell_px: \(/{getline a; getline b; gsub(/[ ,]/,"",a); gsub(/[ ,]/,"",b); print a, b}' "$report" | tail -1)
  # The text area's top-left in the screenshot: xterm's starts at (3, 3) (its window border and
  # 2-pixel internal border; the offset where its sixel matches best); kitty centres the cell
  # grid in its 960x640 window.
  local x0=3 y0=3
  if [[ $name == kitty* ]]; then
    x0=$(( (960 % cw) / 2 ))
    y0=$(( (640 % ch) / 2 ))
  fi
  convert "$OUT/$name-screen.png" -crop "${sw}x${sh}+${x0}+${y0}" +repage "$OUT/$name-region.png"
  convert "$report.png" -resize "${sw}x${sh}!" "$OUT/$name-expected.png"
  local rmse verdict=FAIL
  rmse=$(compare -metric RMSE "$OUT/$name-region.png" "$OUT/$name-expected.png" null: 2>&1 | sed -n 's/^[0-9.e+-]* (\([0-9.e+-]*\))$/\1/p')
  if [ -z "$rmse" ]; then
    rmse="(compare failed)"
  elif awk -v r="$rmse" -v t="$([ "$mode" = Cells ] && echo "$TOLERANCE" || echo "$EXACT")" 'BEGIN{exit !(r <= t)}'; then
    verdict=ok
  fi
  printf '%-16s mode %-6s region %sx%s+%s+%s  RMSE %s  %s\n' "$name" "$mode" "$sw" "$sh" "$x0" "$y0" "$rmse" "$verdict" \
    | tee -a "$OUT/summary.txt"
}

: >"$OUT/summary.txt"
S=$SECONDS_SHOWN
# Inside tmux the demo starts a second late: tmux passes nothing through before its client has
# attached to the new session (a player started from a running tmux pane never meets this).
B="sleep 1; env GRAPHICS_DEMO_BUDGET_MS=$GRAPHICS_DEMO_BUDGET_MS"
if [ -z "${PLAYER_ONLY:-}" ]; then
run kitty "${KITTY[@]}" "$DEMO" auto "$OUT/kitty.txt" $S
run kitty-direct "${KITTY[@]}" env SSH_TTY=/dev/pts/fake "$DEMO" auto "$OUT/kitty-direct.txt" $S
run xterm "${XTERM[@]}" -e "$DEMO" auto "$OUT/xterm.txt" $S
run kitty-tmux-on "${KITTY[@]}" tmux -L tp-on -f "$OUT/tmux-on.conf" new-session "$B $DEMO auto $OUT/kitty-tmux-on.txt $S"
run kitty-tmux-off "${KITTY[@]}" tmux -L tp-off -f "$OUT/tmux-off.conf" new-session "$B $DEMO auto $OUT/kitty-tmux-off.txt $S"
run xterm-tmux "${XTERM[@]}" -e tmux -L tp-x -f "$OUT/tmux-on.conf" new-session "$B $DEMO auto $OUT/xterm-tmux.txt $S"
fi

# The cell size each terminal reported to the probe (graphics_demo's reports, this setup):
# where the picture's region starts and how many cells it covers.
KITTY_CELL=${KITTY_CELL:-9x18}
XTERM_CELL=${XTERM_CELL:-6x13}

# run_player NAME WxH X0 Y0 TERMINAL-COMMAND... : plays in the terminal and compares the
# screen's WxH region at (X0, Y0) (where the picture is shown: the cell area above the status
# row; for sixel its whole 6-pixel bands) with the player's own screenshot scaled to it. The
# terminal command ends with the shell command to run (the last argument, run by `sh -c`).
run_player() {
  local name=$1 region=$2 x0=$3 y0=$4; shift 4
  local dir="$OUT/play-$name"
  rm -rf "$dir"; mkdir -p "$dir"
  # A second's wait first: terminals under Xvfb answer their first query late at window start
  # (longer than the player's 150 ms), and then the player would rightly choose cells.
  "$@" "sleep 1; cd $dir && exec $TIDEPOOL play pool --graphics auto --rain 0 --breeze 0 --seed 1 2>$dir/stderr.txt" &
  local pid=$!
  sleep 5
  local win
  win=$(xdotool search --sync --onlyvisible --pid "$pid" 2>/dev/null | head -1)
  [ -z "$win" ] && win=$(xdotool search --onlyvisible --name '.' 2>/dev/null | tail -1)
  xdotool windowfocus "$win" 2>/dev/null
  for key in space space space; do xdotool key --window "$win" "$key"; sleep 0.3; done
  sleep 1
  xdotool key --window "$win" p; sleep 1
  xdotool key --window "$win" s; sleep 2
  import -window root "$OUT/play-$name-screen.png"
  xdotool key --window "$win" q; sleep 1
  kill "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
  local shot
  shot=$(ls "$dir"/tidepool-pool-*.png 2>/dev/null | head -1)
  if [ -z "$shot" ]; then
    printf '%-18s no player screenshot (keys did not arrive?)\n' "play-$name" | tee -a "$OUT/summary.txt"
    return
  fi
  local pw ph sw=${region%x*} sh=${region#*x}
  read -r pw ph < <(identify -format '%w %h' "$shot")
  convert "$OUT/play-$name-screen.png" -crop "${sw}x${sh}+${x0}+${y0}" +repage "$OUT/play-$name-region.png"
  convert "$shot" -resize "${sw}x${sh}!" "$OUT/play-$name-expected.png"
  local rmse
  rmse=$(compare -metric RMSE "$OUT/play-$name-region.png" "$OUT/play-$name-expected.png" null: 2>&1 | sed -n 's/^[0-9.e+-]* (\([0-9.e+-]*\))$/\1/p')
  local verdict=FAIL
  if [ -n "$rmse" ] && awk -v r="$rmse" -v t="$PLAYER_TOLERANCE" 'BEGIN{exit !(r <= t)}'; then verdict=ok; fi
  printf '%-18s picture %sx%s region %sx%s+%s+%s  RMSE %s  %s\n' "play-$name" "$pw" "$ph" "$sw" "$sh" "$x0" "$y0" "${rmse:-?}" "$verdict" \
    | tee -a "$OUT/summary.txt"
}
kcw=${KITTY_CELL%x*} kch=${KITTY_CELL#*x} xcw=${XTERM_CELL%x*} xch=${XTERM_CELL#*x}
kx=$(( (960 % kcw) / 2 )); ky=$(( (640 % kch) / 2 ))
# kitty's 960x640 window: every row but the last; xterm's 120x40 cells: 39 rows, for sixel in
# whole 6-pixel bands.
KITTY_AREA=$(( 960 / kcw * kcw ))x$(( (640 / kch - 1) * kch ))
XTERM_AREA=$(( 120 * xcw ))x$(( 39 * xch ))
XTERM_SIXEL=$(( 120 * xcw ))x$(( 39 * xch / 6 * 6 ))
run_player kitty "$KITTY_AREA" "$kx" "$ky" "${KITTY[@]}" sh -c
run_player xterm "$XTERM_SIXEL" 3 3 "${XTERM[@]}" -e sh -c
run_player kitty-tmux "$KITTY_AREA" "$kx" "$ky" "${KITTY[@]}" tmux -L tp-pon -f "$OUT/tmux-on.conf" new-session
run_player xterm-tmux "$XTERM_AREA" 3 3 "${XTERM[@]}" -e tmux -L tp-px -f "$OUT/tmux-on.conf" new-session
echo "screenshots and reports in $OUT"
