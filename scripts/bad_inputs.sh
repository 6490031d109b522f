#!/usr/bin/env bash
# Feeds tidepool every kind of bad input and prints a Markdown table: the input, the command,
# the first line tidepool printed and its exit status (then three checks of what must not be
# lost). Needs python3 with Pillow to make the test images. Usage: scripts/bad_inputs.sh
set -uo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
cargo build --release --quiet --manifest-path "$repo/Cargo.toml"
T="$repo/target/release/tidepool"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
rm -rf adir afile full; mkdir -p adir; echo hi > afile
: > empty.png
echo "this is not a picture" > text.png
$T render pool --size 64x48 --out ok.png >/dev/null 2>&1
head -c 300 ok.png > trunc.png
$T render pool --size 64x48 --frames 3 --out anim.png >/dev/null 2>&1
python3 - <<'PY'
from PIL import Image
import struct, zlib
im = Image.open('ok.png').convert('RGB')
im.save('ok.jpg', quality=90)
d = open('ok.jpg','rb').read(); open('corrupt.jpg','wb').write(d[:len(d)//2])
im.convert('L').save('grey.png')
im.convert('P').save('palette.png')
im.convert('I;16').save('grey16.png')
# a PNG whose header claims 100000x100000
def chunk(t, b): return struct.pack('>I', len(b)) + t + b + struct.pack('>I', zlib.crc32(t+b) & 0xffffffff)
png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 100000, 100000, 8, 2, 0, 0, 0)) + chunk(b'IDAT', zlib.compress(b'\0'*1000)) + chunk(b'IEND', b'')
open('huge.png','wb').write(png)
PY
cp ok.png keep.png; before=$(sha256sum keep.png)
printf '{"tidepool_replay":1,"version":"0.1.0","scene":"pool","seed":1,"size":[64,48],"options":{"background":null,"caustics":true,"damping":"5","depth":24.0,"rain":0.0,"refraction":"auto","shading":true,"sun":"315,60"}}\n{"step":3,"stone":[10,10,3,48]}\n{"step":9,"en' > trunc.jsonl
printf 'hello\n' > garbage.jsonl
printf '{"tidepool_replay":2,"version":"0.9.0","scene":"pool","seed":1,"size":[64,48],"options":{}}\n{"step":9,"end":true}\n' > future.jsonl
options='"options":{"background":null,"caustics":true,"damping":"5","depth":24.0,"rain":0.0,"refraction":"auto","shading":true,"sun":"315,60"}'
printf '{"tidepool_replay":1,"scene":"pool","seed":1,"size":[60000,60000],%s}\n{"step":9,"end":true}\n' "$options" > huge.jsonl
printf '{"tidepool_replay":1,"scene":"pool","seed":1,"size":[64,48],%s}\n{"step":18446744073709551615,"end":true}\n' "$options" > forever.jsonl
python3 - "$options" <<'PY'
import sys
with open('crowded.jsonl', 'w') as f:
    f.write('{"tidepool_replay":1,"scene":"pool","seed":1,"size":[64,48],%s}\n' % sys.argv[1])
    f.writelines('{"step":%d,"clear":true}\n' % i for i in range(1_000_001))
    f.write('{"step":1000001,"end":true}\n')
PY

row() {  # row "description" command...
  local out code start end
  out=$("${@:2}" 2>&1 >/dev/null | head -1); code=${PIPESTATUS[0]}
  start=$(date +%s.%N)
  "${@:2}" >/dev/null 2>/dev/null; code=$?
  end=$(date +%s.%N)
  printf '| %s | `%s` | %s | %s | %.2f |\n' "$1" "$(echo "${@:2}" | sed "s|$T|tidepool|")" "${out//|/\\|}" "$code" "$(awk "BEGIN { print $end - $start }")"
}
{
echo '| input | command | what tidepool printed (first line) | exit | seconds |'
echo '|---|---|---|---|---|'
row "missing background" $T render pool --background missing.png --out o.png
row "a directory" $T render pool --background adir --out o.png
row "zero bytes" $T render pool --background empty.png --out o.png
row "truncated PNG" $T render pool --background trunc.png --out o.png
row "corrupt JPEG" $T render pool --background corrupt.jpg --out o.png
row "text named .png" $T render pool --background text.png --out o.png
row "header claims 100000x100000" $T render pool --background huge.png --out o.png
row "animated PNG (works)" $T render pool --background anim.png --out o.png
row "16-bit PNG (works)" $T render pool --background grey16.png --out o.png
row "greyscale PNG (works)" $T render pool --background grey.png --out o.png
row "palette PNG (works)" $T render pool --background palette.png --out o.png
row "JPEG (works)" $T render pool --background ok.jpg --out o.png
row "corrupt sea texture" $T render ocean --texture corrupt.jpg --out o.png
row "huge sea texture" $T render ocean --texture huge.png --out o.png
row "size 0" $T render pool --size 0x0
row "negative size" $T render pool --size -5x10
row "non-numeric size" $T render pool --size abcx10
row "side > 16384" $T render pool --size 20000x100
row "> 64 megapixels" $T render pool --size 9000x9000
row "> 64 MP with supersampling" $T render ocean --size 6000x6000 --ssaa 2
row "lake > 64 MP with supersampling" $T render lake --size 8000x4000 --ssaa 2
row "NaN refraction" $T render pool --refraction NaN
row "infinite rain" $T render pool --rain inf
row "negative rain" $T render pool --rain -1
row "damping 0" $T render pool --damping 0
row "wind below 0" $T render ocean --wind -1
row "wind above 60" $T render ocean --wind 61
row "NaN wind" $T render ocean --wind nan
row "Beaufort 13" $T render ocean --beaufort 13
row "lake wind 31" $T render lake --wind 31
row "octaves 0" $T render lake --octaves 0
row "persistence 2" $T render lake --persistence 2
row "negative seed" $T render ocean --seed -1
row "stone outside the picture (clipped)" $T render pool --size 64x48 --stone 1000,1000,20 --stone -5,-5,10 --out o.png
row "huge --steps (just runs)" $T render pool --size 64x48 --steps 200000 --out o.png
row "stone radius 0" $T render pool --stone 10,10,0
row "GIF at 60 fps" $T render pool --frames 10 --fps 60 --out a.gif
row "animation to stdout" $T render pool --frames 10 --out -
row "frames 0" $T render pool --frames 0
row "pattern without .png" $T render pool --frames 3 --out 'f_{frame}.gif'
row "missing output folder" $T render pool --out nowhere/o.png
row "output under a regular file" $T render pool --out afile/o.png
row "output is a directory" $T render pool --out adir
row "full disk (/dev/full)" $T render pool --out /dev/full --format png
row "unknown extension" $T render pool --out o.jpg
row "replay missing" $T render pool --replay nothere.jsonl
row "replay truncated" $T render pool --replay trunc.jsonl --out o.png
row "replay garbage" $T render pool --replay garbage.jsonl --out o.png
row "replay from another version" $T render pool --replay future.jsonl --out o.png
row "replay with --size" $T render pool --replay trunc.jsonl --size 10x10
row "replay of 60000x60000 pixels" $T render pool --replay huge.jsonl --out o.png
row "replay ending at step 2^64-1" $T render pool --replay forever.jsonl --out o.png
row "replay of 1,000,002 events" $T render pool --replay crowded.jsonl --out o.png
row "player, stdout not a terminal" $T play
row "unknown scene" $T play river
row "ocean --extent without --heightmap" $T render ocean --extent 100
}
# An existing file at the output path survives every failed write:
$T render pool --out keep.png --background trunc.png >/dev/null 2>&1
after=$(sha256sum keep.png); [ "$before" = "$after" ] && echo "an existing keep.png survived a failed write: yes" || echo "an existing keep.png survived a failed write: NO"
$T render pool --out - --size 200x100 | head -c 100 >/dev/null; echo "render --out - | head -c 100: exit ${PIPESTATUS[0]}, stderr $($T render pool --out - --size 200x100 2>&1 >/dev/null | head -c 100 | wc -c) bytes"
echo "temporary files left: $(ls -a | grep -c '\.tmp')"
exit 0
