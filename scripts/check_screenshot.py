"""Checks a screenshot of a recording in the Rerun viewer: not blank, and no
view of the shipped layout empty.

usage: python check_screenshot.py {calibration,grid,epuck,agent} SHOT.png [--self-test]

The layouts are the recordings' default blueprints with the side panels
folded (sim/src/record.rs): every view is a cell of a known grid. Inside
each cell (inset past its tab bar and margins) some pixels must differ
clearly from the cell's own background: an empty view (a wrong entity path,
a missing entity, a broken blueprint) is one flat colour. `--self-test`
paints each cell flat in turn and checks that the check then fails.
"""

import sys

if __name__ == "__main__" and {"-h", "--help"} & set(sys.argv[1:]):
    print(__doc__.strip())
    sys.exit(0)


import numpy as np
from PIL import Image

# The views area, as fractions of the window: below the top bar, above the
# time bar.
TOP, BOTTOM = 0.03, 0.97

# (x0, x1, rows) per column: rows are (name, share).
LAYOUTS = {
    "calibration": [
        (0.0, 0.5, [("grand average FCz", 1), ("grand average Cz", 1), ("grand average Fz", 1)]),
        (0.5, 1.0, [("topography", 1), ("summary", 1)]),
    ],
    "grid": [
        (0.0, 0.6, [("grid scene", 1), ("events", 1)]),
        (0.6, 1.0, [("p(error)", 1), ("belief", 1), ("EEG", 1), ("visited states", 1)]),
    ],
    "epuck": [
        (0.0, 0.6, [("arena", 1), ("events", 1)]),
        (0.6, 1.0, [("belief per city", 1), ("p(error) and T_e", 1), ("EEG", 1)]),
    ],
    # Episodes of errp.gym.EpuckEnv: an agent drives, so no belief view.
    "agent": [
        (0.0, 0.6, [("arena", 1), ("events", 1)]),
        (0.6, 1.0, [("p(error) and T_e", 1), ("EEG", 1)]),
    ],
}

# A pixel is ink when a channel differs from the cell's background by more
# than this; a view is empty with less than MIN_INK of its cell inked.
INK_LEVEL = 48
MIN_INK = 0.003
INSET = 0.12


def cells(kind: str, width: int, height: int):
    for x0, x1, rows in LAYOUTS[kind]:
        total = sum(share for _, share in rows)
        y = TOP
        for name, share in rows:
            h = (BOTTOM - TOP) * share / total
            box = (x0, y, x1, y + h)
            y += h
            bx0, by0, bx1, by1 = box
            dx, dy = (bx1 - bx0) * INSET, (by1 - by0) * INSET
            yield name, (
                int((bx0 + dx) * width),
                int((by0 + dy) * height),
                int((bx1 - dx) * width),
                int((by1 - dy) * height),
            )


def ink(image: Image.Image, box) -> float:
    region = np.asarray(image.crop(box).convert("RGB"), dtype=np.int32).reshape(-1, 3)
    packed = (region[:, 0] << 16) | (region[:, 1] << 8) | region[:, 2]
    top = int(np.bincount(packed).argmax())
    background = np.array([top >> 16, (top >> 8) & 255, top & 255])
    return float((np.abs(region - background).max(axis=1) > INK_LEVEL).mean())


def problems(kind: str, image: Image.Image) -> list[str]:
    out = []
    grey = image.convert("L")
    lo, hi = grey.getextrema()
    if hi - lo < 32:
        out.append(f"the screenshot is blank (grey levels {lo}-{hi})")
    for name, box in cells(kind, *image.size):
        share = ink(image, box)
        if share < MIN_INK:
            out.append(f"view '{name}' is empty ({100 * share:.2f} % of it drawn)")
    return out


def main(kind: str, path: str, self_test: bool) -> None:
    image = Image.open(path)
    found = problems(kind, image)
    if found:
        sys.exit(f"{path}: " + "; ".join(found))
    if self_test:
        for name, box in cells(kind, *image.size):
            blanked = image.convert("RGB")
            blanked.paste((12, 12, 12), box)
            assert any(name in p for p in problems(kind, blanked)), name
    shares = ", ".join(
        f"{name} {100 * ink(image, box):.1f} %" for name, box in cells(kind, *image.size)
    )
    n = sum(1 for _ in cells(kind, 1, 1))
    print(f"{path}: {n} views drawn ({shares})")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], "--self-test" in sys.argv[3:])
