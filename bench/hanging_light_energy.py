"""Issue 34's measurement: where a lit closed room loses light around a light
hanging under its ceiling (native/README.md, "Energy around a hanging light").

    PYTHONPATH=<build>/addon/radiosity /usr/bin/python3 bench/hanging_light_energy.py [--oracles a,b] [--quick]

Prints two tables:
- balance: a closed 4 x 4 x 3 m room, reflectance rho everywhere, lit by a
  0.6 m square one-sided light whose up-facing cover reflects like the walls,
  `gap` under the ceiling: absorbed over emitted power (1 in a closed room);
- furnace: the same room with every face emitting 0.7 and reflecting rho: each
  face's area-weighted radiance against 0.7 / (1 - rho), the value a closed
  furnace has everywhere; a face below it is where its links' form factors
  sum to less than the closed room's 1.
"""

import argparse
import math
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "native"))
import _radiosity as rad  # noqa: E402
from test_hanging_lamp import LAMP_SIDE, hanging_lamp_room as room  # noqa: E402
from test_energy import LAMP_RADIANCE  # noqa: E402
from test_solver import absorbed_power, polygon_areas  # noqa: E402

FACES = ("floor", "ceiling", "wall -y", "wall +y", "wall -x", "wall +x", "light", "cover")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--oracles", default="perceptual")
    parser.add_argument("--quick", action="store_true", help="rho 0.9 and quality 0.3 only")
    args = parser.parse_args()
    rhos, qualities = ((0.9,), (0.3,)) if args.quick else ((0.5, 0.9, 0.99), (0.3, 0.5))
    gaps = (0.001, 0.01, 0.5)

    print("| rho | gap (m) | oracle | quality | absorbed / emitted | elements |\n|---|---|---|---|---|---|")
    for rho in rhos:
        for gap in gaps:
            for oracle in args.oracles.split(","):
                for quality in qualities:
                    b = room(rho, gap)
                    result = rad.solve(b.scene(rad), oracle=oracle, quality=quality)
                    ratio = absorbed_power(b, result)[0] / (math.pi * LAMP_RADIANCE * LAMP_SIDE**2)
                    print(f"| {rho} | {gap} | {oracle} | {quality} | {ratio:.5f} | {result.stats['elements']} |",
                          flush=True)

    print("\n| rho | gap (m) | " + " | ".join(FACES) + " |\n|---|---|" + "---|" * len(FACES))
    for rho in rhos:
        for gap in gaps:
            result = rad.solve(room(rho, gap, emission=0.7).scene(rad), oracle="perceptual", quality=qualities[0])
            radiance = 0.7 + rho * result.irradiance[:, 0]
            areas = polygon_areas(result)
            cells = []
            for face in range(len(FACES)):
                # The room's two-sided walls' outsides see nothing: left out.
                inside = (result.source_face == face) & (result.irradiance[:, 0] > 0)
                mean = (radiance[inside] * areas[inside]).sum() / areas[inside].sum()
                cells.append(f"{mean / (0.7 / (1 - rho)) - 1:+.2%}")
            print(f"| {rho} | {gap} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
