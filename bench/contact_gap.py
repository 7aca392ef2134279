"""Issue 12's numbers, re-measured in one go (runs inside Blender): the Cornell
box's light-gap table and the contact scenes, against path-traced references.

    blender -b --factory-startup --python bench/contact_gap.py -- [--build build] [--quick] [--images DIR]

Prints, as markdown tables:
- the gap table: radiosity / Cycles mean brightness (mean linear luminance,
  emitter pixels left out) of the Cornell box with its light 0.1 mm, 1 mm,
  1 cm and 5 cm under the ceiling, each oracle at quality 0.5, and the median
  8 x 8-block error of the same solves;
- the acceptance matrix of tests/blender/test_contact.py (signed exposure
  error and median block error per case, oracle and quality; --quick: quality
  0.5 only);
- each reference's own noise.
The measurement is the test's (tests/blender/contact_agreement.py), with the
same cached references (<build>/contact_cache): after the first run only the
solves and their 8-sample renders cost time (--quick: about a minute).
"""

import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
import in_blender  # noqa: E402


def main():
    args = in_blender.arguments("contact_gap.py", "quality 0.5 only")
    radiosity = in_blender.load_addon(args.build)
    import contact_agreement as ca
    import image_agreement

    started = time.perf_counter()
    gap_cases = [label for _, label in ca.GAPS]
    matrix_cases = ["cornell_box", "cornell_box_1mm", "cornell_box_1cm", "box_on_floor", "lamp_on_table",
                    "picture_on_wall"]
    qualities = (0.5,) if args.quick else ca.QUALITIES
    results, noise = {}, {}
    for label in dict.fromkeys(gap_cases + matrix_cases):
        scene = ca.build_case(label)
        reference = ca.Reference(label, scene)
        noise[label] = (reference.noise(), len(reference.seeds), reference.rendered)
        renders = {}
        for oracle in ca.ORACLES:
            for quality in (qualities if label in matrix_cases else (0.5,)):
                start = time.perf_counter()
                image, stats = ca.solve_and_render(scene, oracle, quality)
                e = image_agreement.compare(image, reference.image, reference.mask)
                results[label, oracle, quality] = dict(e, elements=stats.elements, seconds=time.perf_counter() - start)
                renders["%s_%.1f" % (oracle.lower(), quality)] = image
                print("  %-16s %-10s q=%.1f exposure %+6.1f %%  block %5.1f %%  %6d elements  %.1f s" % (
                    label, oracle.lower(), quality, 100 * e["exposure"], 100 * e["block"], stats.elements,
                    results[label, oracle, quality]["seconds"]), flush=True)
        if args.images:
            ca.save_pngs(args.images, label, reference, renders)

    names = [o.lower() for o in ca.ORACLES]
    print("\nLight's gap under the ceiling of the Cornell box: radiosity / Cycles mean brightness "
          "(median 8x8-block error), quality 0.5\n")
    print("| light's gap under the ceiling | %s |" % " | ".join(names))
    print("|---|%s" % ("---|" * len(names)))
    for gap, label in ca.GAPS:
        cells = ["%.3f (%.1f %%)" % (1 + results[label, o, 0.5]["exposure"], 100 * results[label, o, 0.5]["block"])
                 for o in ca.ORACLES]
        print("| %s | %s |" % (gap, " | ".join(cells)))

    print("\nAcceptance (test_contact.py: |exposure| < 3 %, median block error < 6 %; x: outside): "
          "exposure error / median block error\n")
    header = ["%s %.1f" % (o, q) for o in names for q in qualities]
    print("| case | %s |" % " | ".join(header))
    print("|---|%s" % ("---|" * len(header)))
    failed = 0
    for label in matrix_cases:
        cells = []
        for oracle in ca.ORACLES:
            for q in qualities:
                r = results[label, oracle, q]
                ok = abs(r["exposure"]) < 0.03 and r["block"] < 0.06
                failed += not ok
                cells.append("%+.1f %% / %.1f %%%s" % (100 * r["exposure"], 100 * r["block"], "" if ok else " x"))
        print("| %s | %s |" % (label, " | ".join(cells)))

    print("\nReferences (%d x %d, seeds of %d samples): their own noise, exposure / median block\n"
          % (*ca.RESOLUTION, ca.REFERENCE_SAMPLES))
    for label, (n, seeds, rendered) in noise.items():
        print("  %-16s %d seeds: %.3f %% / %.2f %%%s" % (label, seeds, 100 * n["exposure"], 100 * n["block"],
                                                       "" if rendered else " (cached)"))
    print("\n%d of %d acceptance cases outside the tolerances; %.0f s" % (
        failed, len(matrix_cases) * len(ca.ORACLES) * len(qualities), time.perf_counter() - started), flush=True)
    radiosity.unregister()


if __name__ == "__main__":
    main()
