#!/usr/bin/env python3
"""Reads tidepool's OpenEXR sea maps with an independent reader (the OpenEXR Python bindings,
the Academy Software Foundation's own library) and checks them against the other files:

  - height.exr (Y) and displacement.exr (R, G, B) equal height.npy and displacement.npy
    within half-float precision (half the spacing of halves at each value);
  - normal.exr (R, G, B) is unit length and equals normal.png within its 8-bit step;
  - foam.exr (Y) equals foam.png within its 8-bit step;
  - every EXR tiles: the step across its seam (last column to first, last row to first) is
    no larger than the largest step inside it;
  - with --same A B: the EXR files of folder A are the same bytes as folder B's (a loop later).

    python3 scripts/check_exr_maps.py MAPS_DIR [--same OTHER_DIR] [--png PREVIEW.png]

Exits 0 when every check holds, 1 with one line per failed check, and 2 when the reader is
missing (pip install OpenEXR numpy pillow). --png writes the four maps side by side as a
picture (what the reader decoded), for looking at.
"""

import sys
from pathlib import Path

try:
    import numpy as np
    import OpenEXR
    from PIL import Image
except ImportError as e:  # fail loudly: the check cannot run without its reader
    print(f"check_exr_maps: the independent reader is missing ({e}); pip install OpenEXR numpy pillow",
          file=sys.stderr)
    sys.exit(2)


def read_exr(path):
    """The channels of an EXR file as float64 arrays by name, with their stored types."""
    with OpenEXR.File(str(path), separate_channels=True) as f:
        channels = f.channels()
        out = {}
        for name, ch in channels.items():
            out[name] = (np.asarray(ch.pixels, dtype=np.float64), ch.type())
        return out


def half_tolerance(values):
    """Half the gap between neighbouring halves at each value (round to nearest), at least the
    smallest subnormal's half."""
    v = np.abs(values).astype(np.float16).astype(np.float64)
    spacing = np.spacing(np.maximum(v, 6.1e-5).astype(np.float16)).astype(np.float64)
    return 0.5 * spacing + 3e-8


def seam_ok(field, failures, name):
    inside = max(np.abs(np.diff(field, axis=0)).max(), np.abs(np.diff(field, axis=1)).max())
    seam = max(np.abs(field[0] - field[-1]).max(), np.abs(field[:, 0] - field[:, -1]).max())
    if not seam <= inside:
        failures.append(f"{name}: the seam steps {seam}, more than any step inside ({inside})")


def check(folder, failures):
    folder = Path(folder)
    height = np.load(folder / "height.npy").astype(np.float64)
    displacement = np.load(folder / "displacement.npy").astype(np.float64)
    normal_png = np.asarray(Image.open(folder / "normal.png").convert("RGB"), dtype=np.float64) / 127.5 - 1.0
    foam_png = np.asarray(Image.open(folder / "foam.png").convert("L"), dtype=np.float64) / 255.0
    exr = {name: read_exr(folder / f"{name}.exr") for name in ["height", "displacement", "normal", "foam"]}
    for name, channels in exr.items():
        for ch, (_, kind) in channels.items():
            if kind != OpenEXR.HALF:
                failures.append(f"{name}.exr channel {ch} is {kind}, not half float")
    h = exr["height"]["Y"][0]
    d = np.stack([exr["displacement"][c][0] for c in "RGB"], axis=-1)
    n = np.stack([exr["normal"][c][0] for c in "RGB"], axis=-1)
    f = exr["foam"]["Y"][0]
    for name, got, want in [("height", h, height), ("displacement", d, displacement)]:
        if got.shape != want.shape:
            failures.append(f"{name}.exr is {got.shape}, {name}.npy {want.shape}")
            continue
        err = np.abs(got - want) - half_tolerance(want)
        if err.max() > 0:
            failures.append(f"{name}.exr differs from {name}.npy by more than half precision "
                            f"(worst {np.abs(got - want).max()} at {np.unravel_index(err.argmax(), err.shape)})")
    length = np.sqrt((n ** 2).sum(axis=-1))
    if np.abs(length - 1).max() > 2e-3:
        failures.append(f"normal.exr is not unit length (worst {np.abs(length - 1).max()})")
    if np.abs(n - normal_png).max() > 1.0 / 127.5 + 1e-3:
        failures.append(f"normal.exr differs from normal.png by {np.abs(n - normal_png).max()}")
    if np.abs(f - foam_png).max() > 0.5 / 255 + 1e-3:
        failures.append(f"foam.exr differs from foam.png by {np.abs(f - foam_png).max()}")
    seam_ok(h, failures, "height.exr")
    for k, c in enumerate("RGB"):
        seam_ok(d[..., k], failures, f"displacement.exr {c}")
    return h, d, n, f


def preview(path, h, d, n, f):
    """The four maps side by side as the reader decoded them, with a 2x2 tiling of the height."""
    def grey(a):
        lo, hi = np.percentile(a, 0.5), np.percentile(a, 99.5)
        return np.clip((a - lo) / max(hi - lo, 1e-9) * 255, 0, 255).astype(np.uint8)
    tiles = [
        np.stack([grey(np.tile(h, (2, 2)))[::2, ::2]] * 3, axis=-1),
        np.stack([grey(d[..., k]) for k in range(3)], axis=-1),
        np.clip((n + 1) * 127.5, 0, 255).astype(np.uint8),
        np.stack([np.clip(f * 255, 0, 255).astype(np.uint8)] * 3, axis=-1),
    ]
    gap = np.full((h.shape[0], 8, 3), 255, np.uint8)
    row = np.concatenate([x for t in tiles for x in (t, gap)][:-1], axis=1)
    Image.fromarray(row).save(path)


def main(argv):
    if not argv or argv[0].startswith("-"):
        print(__doc__, file=sys.stderr)
        return 2
    failures = []
    h, d, n, f = check(argv[0], failures)
    if "--same" in argv:
        other = Path(argv[argv.index("--same") + 1])
        for name in ["height", "displacement", "normal", "foam"]:
            if (Path(argv[0]) / f"{name}.exr").read_bytes() != (other / f"{name}.exr").read_bytes():
                failures.append(f"{name}.exr differs from {other / (name + '.exr')}")
    if "--png" in argv:
        preview(argv[argv.index("--png") + 1], h, d, n, f)
    for line in failures:
        print(f"check_exr_maps: {line}")
    if not failures:
        print(f"check_exr_maps: {argv[0]}: height, displacement, normal and foam read back by OpenEXR "
              f"{OpenEXR.__version__}: within half precision of the .npy/.png, tiling")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
