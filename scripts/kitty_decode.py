#!/usr/bin/env python3
"""An independent reader of the kitty graphics protocol: turns a byte stream into the images a
terminal would hold, written from the protocol's documentation (kitty's
docs/graphics-protocol.rst) and sharing no code with tidepool's encoder or its Rust decoder.

    python3 scripts/kitty_decode.py STREAM OUTDIR

Writes OUTDIR/image-ID.ppm (binary P6) for every image held at the end of the stream and prints
one line per image: `ID WIDTH HEIGHT`. Exit status 2 with one line on stderr for anything it does
not understand (so a test fails loudly instead of passing on a misread stream).

Understood, as documented: APC commands `ESC _ G <control> ; <payload> ESC \\`, also inside tmux
passthrough (`ESC P tmux ; ... ESC \\` with every inner ESC doubled); control keys `key=value`
separated by commas; chunked transmission (`m=1` on every chunk but the last; only the first
chunk's keys count, later chunks carry `m` and may repeat `a=f`/`q`); base64 payloads; `t=d`
(direct) only; `o=z` (RFC 1950 zlib); formats `f=24` (RGB), `f=32` (RGBA, alpha dropped) and
`f=100` (PNG: 8-bit RGB, RGBA or palette of 1-8 bits a pixel, non-interlaced, decoded here with
zlib and the five PNG row filters); actions `a=t`/`a=T` (transmit: the image is replaced), `a=f` (frame data with
`r=1`: replace the `s`x`v` rectangle at `x`,`y` of the root frame, `X=1` replacement), `a=d`
(`d=i`/`d=I` by id, anything else: all). Other actions (placements, queries) change no pixels.
"""

import base64
import struct
import sys
import zlib


class Misread(Exception):
    pass


def parse_control(text):
    keys = {}
    for pair in text.split(","):
        if not pair:
            continue
        if "=" not in pair:
            raise Misread(f"control key without value: {pair!r}")
        k, v = pair.split("=", 1)
        if len(k) != 1:
            raise Misread(f"control key of more than one letter: {k!r}")
        keys[k] = v
    return keys


def unwrap_tmux(data):
    """Replaces every tmux passthrough wrapper by its inner bytes (ESC ESC -> ESC)."""
    out = bytearray()
    i = 0
    begin = b"\x1bPtmux;"
    while i < len(data):
        if data.startswith(begin, i):
            j = i + len(begin)
            while True:
                if j >= len(data):
                    raise Misread("a tmux passthrough sequence is cut short")
                if data[j] == 0x1B:
                    nxt = data[j + 1 : j + 2]
                    if nxt == b"\x1b":
                        out.append(0x1B)
                        j += 2
                        continue
                    if nxt == b"\\":
                        j += 2
                        break
                    raise Misread("a lone ESC inside a tmux passthrough sequence")
                out.append(data[j])
                j += 1
            i = j
        else:
            out.append(data[i])
            i += 1
    return bytes(out)


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def decode_png(data):
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise Misread("f=100 payload is not a PNG")
    pos, idat, palette, header = 8, bytearray(), None, None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"PLTE":
            palette = body
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    if header is None:
        raise Misread("PNG without IHDR")
    w, h, depth, colour, _, _, interlace = header
    # 8 bits a channel, or a palette of 1, 2, 4 or 8 bits a pixel (the stream's palette PNG).
    depth_ok = depth == 8 or (colour == 3 and depth in (1, 2, 4))
    if not depth_ok or interlace != 0 or colour not in (2, 3, 6):
        raise Misread(f"PNG depth {depth} colour type {colour} interlace {interlace} not understood")
    channels = {2: 3, 3: 1, 6: 4}[colour]
    raw = zlib.decompress(bytes(idat))
    # Bytes a row; the filters look one byte back when pixels are smaller than a byte.
    stride = (w * channels * depth + 7) // 8
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(h):
        kind, line = raw[i], bytearray(raw[i + 1 : i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = prev[x]
            c = prev[x - channels] if x >= channels else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                line[x] = (line[x] + paeth(a, b, c)) & 255
            elif kind != 0:
                raise Misread(f"PNG filter {kind}")
        rows.append(bytes(line))
        prev = line
    rgb = bytearray()
    for line in rows:
        if colour == 2:
            rgb += line
        elif colour == 6:
            for x in range(w):
                rgb += line[4 * x : 4 * x + 3]
        else:
            per_byte = 8 // depth
            for x in range(w):
                shift = 8 - depth - (x % per_byte) * depth
                idx = (line[x // per_byte] >> shift) & ((1 << depth) - 1)
                if 3 * idx + 3 > len(palette):
                    raise Misread(f"palette index {idx} beyond the PLTE")
                rgb += palette[3 * idx : 3 * idx + 3]
    return w, h, bytes(rgb)


def pixels(keys, payload, w, h):
    if keys.get("t", "d") != "d":
        raise Misread(f"medium t={keys['t']} not understood (direct only)")
    data = base64.b64decode(payload, validate=True)
    if keys.get("o") == "z":
        data = zlib.decompress(data)
    elif "o" in keys:
        raise Misread(f"compression o={keys['o']}")
    fmt = keys.get("f", "32")
    if fmt == "100":
        pw, ph, rgb = decode_png(data)
        if (pw, ph) != (w, h) and (w, h) != (0, 0):
            raise Misread(f"a {pw}x{ph} PNG for s={w},v={h}")
        return pw, ph, rgb
    size = {"24": 3, "32": 4}.get(fmt)
    if size is None:
        raise Misread(f"format f={fmt}")
    if len(data) != w * h * size:
        raise Misread(f"{len(data)} bytes for {w}x{h} of {size} bytes a pixel")
    if size == 4:
        data = b"".join(data[i : i + 3] for i in range(0, len(data), 4))
    return w, h, data


def decode(stream):
    stream = unwrap_tmux(stream)
    images, pending = {}, None
    i = 0
    while True:
        start = stream.find(b"\x1b_G", i)
        if start < 0:
            break
        end = stream.find(b"\x1b\\", start)
        if end < 0:
            raise Misread("an APC command is not terminated")
        body = stream[start + 3 : end].decode("ascii")
        i = end + 2
        control, _, payload = body.partition(";")
        keys = parse_control(control)
        if pending is not None:
            first, data = pending
            data += payload
            if keys.get("m") == "1":
                pending = (first, data)
                continue
            keys, payload, pending = first, data, None
        elif keys.get("m") == "1":
            pending = (keys, payload)
            continue
        num = lambda k: int(keys.get(k, "0"))
        action = keys.get("a", "t")
        if action in ("t", "T"):
            w, h, rgb = pixels(keys, payload, num("s"), num("v"))
            images[num("i")] = [w, h, bytearray(rgb)]
        elif action == "f":
            if keys.get("r", "1") != "1" or keys.get("X", "0") != "1":
                raise Misread("only replacement edits of the root frame (r=1, X=1) are understood")
            image = images.get(num("i"))
            if image is None:
                raise Misread(f"frame data for unknown image {num('i')}")
            x, y, w, h = num("x"), num("y"), num("s"), num("v")
            w, h, rgb = pixels(keys, payload, w, h)
            iw, ih, canvas = image
            if x + w > iw or y + h > ih:
                raise Misread("frame data outside the image")
            for row in range(h):
                at = ((y + row) * iw + x) * 3
                canvas[at : at + 3 * w] = rgb[row * 3 * w : (row + 1) * 3 * w]
        elif action == "d":
            if keys.get("d", "a") in ("i", "I"):
                images.pop(num("i"), None)
            else:
                images.clear()
    if pending is not None:
        raise Misread("the stream ends inside a chunked transmission")
    return images


def main():
    if len(sys.argv) != 3:
        print("usage: kitty_decode.py STREAM OUTDIR", file=sys.stderr)
        sys.exit(2)
    try:
        with open(sys.argv[1], "rb") as f:
            images = decode(f.read())
    except (Misread, ValueError, zlib.error, UnicodeDecodeError) as e:
        print(f"kitty_decode.py: {e}", file=sys.stderr)
        sys.exit(2)
    for image_id, (w, h, rgb) in sorted(images.items()):
        with open(f"{sys.argv[2]}/image-{image_id}.ppm", "wb") as f:
            f.write(b"P6\n%d %d\n255\n" % (w, h) + bytes(rgb))
        print(image_id, w, h)


if __name__ == "__main__":
    main()
