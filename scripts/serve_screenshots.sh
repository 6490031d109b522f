#!/usr/bin/env bash
# Three OpenSSH clients of different sizes (80x24, 120x40, 160x48) in one shared pool: each a
# tmux pane running `ssh` to `tidepool serve` on 127.0.0.1, one stone from the first, one from
# the third; the panes captured with their colours, painted by examples/terminal_screenshot.rs
# and set side by side (docs/serve/three-clients.png, by Python's pillow).
#
#     cargo build --release --examples && bash scripts/serve_screenshots.sh
#
# Needs tmux, the OpenSSH client and pillow. The server listens on loopback only and is
# stopped at the end (and after 60 s whatever happens).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=target/release/tidepool
port=${SERVE_PORT:-22399}
work=$(mktemp -d)
trap 'kill $server 2>/dev/null || true; for s in 80x24 120x40 160x48; do tmux kill-session -t shot-$s-$$ 2>/dev/null || true; done; rm -rf "$work"' EXIT
timeout 60 "$bin" serve --listen "127.0.0.1:$port" --host-key "$work/host_key" 2>"$work/serve.log" &
server=$!
sleep 1
ssh_cmd="ssh -p $port -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o BatchMode=yes -o LogLevel=ERROR -t player@127.0.0.1"
for size in 80x24 120x40 160x48; do
    cols=${size%x*} rows=${size#*x}
    tmux new-session -d -s "shot-$size-$$" -x "$cols" -y "$rows" "COLORTERM=truecolor TERM=xterm-256color $ssh_cmd"
done
sleep 5
tmux send-keys -t "shot-80x24-$$" space
sleep 0.7
tmux send-keys -t "shot-160x48-$$" space
sleep 1
for size in 80x24 120x40 160x48; do
    cols=${size%x*} rows=${size#*x}
    tmux capture-pane -t "shot-$size-$$" -e -N -p > "$work/$size.ans"
    target/release/examples/terminal_screenshot "$work/$size.ans" "$work/$size.png" "$cols" "$rows"
done
for size in 80x24 120x40 160x48; do tmux send-keys -t "shot-$size-$$" q; done
sleep 0.5
mkdir -p docs/serve
python3 - "$work" docs/serve/three-clients.png <<'PY'
import sys
from PIL import Image
work, out = sys.argv[1], sys.argv[2]
shots = [Image.open(f"{work}/{s}.png").convert("RGB") for s in ("80x24", "120x40", "160x48")]
gap = 16
canvas = Image.new("RGB", (sum(s.width for s in shots) + gap * 2, max(s.height for s in shots)), (40, 40, 40))
x = 0
for s in shots:
    canvas.paste(s, (x, 0))
    x += s.width + gap
canvas.save(out, optimize=True)
print(out, canvas.size)
PY
grep -c "left\|joined" "$work/serve.log" || true
