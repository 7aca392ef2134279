"""What finely tessellated objects cost (runs inside Blender): the
tessellated_room scene (scenes/tessellated_room.py: a UV sphere, then also a
subdivided Suzanne, in a room built with Blender's operators) solved with
exact and sampled visibility, against its path trace.

    blender -b --factory-startup --python bench/tessellated_room.py -- [--build build] [--quick] [--images DIR]

Prints a markdown table (also written to <build>/bench/tessellated_room.md): per case, visibility and oracle at quality 0.5, the
Solve's seconds, elements and links, and the exposure and median 8 x 8-block
errors against the path-traced reference (tests/blender/contact_agreement.py's
measurement and cache). --quick: the sphere case only (about two minutes
after its reference is cached); the Suzanne case takes 20 to 30 minutes.
"""

import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
import in_blender  # noqa: E402

CASES = ("tessellated_sphere", "tessellated_monkey")
VISIBILITIES = ("SAMPLED", "EXACT")
ORACLES = ("STANDARD", "PERCEPTUAL")


def main():
    args = in_blender.arguments("tessellated_room.py", "the sphere case only")
    in_blender.load_addon(args.build)
    import contact_agreement as ca
    import image_agreement

    rows = ["| case | visibility | oracle | seconds | elements | links | exposure | median block |",
            "|---|---|---|---|---|---|---|---|"]
    for label in CASES[:1] if args.quick else CASES:
        scene = ca.build_case(label)
        reference = ca.Reference(label, scene)
        renders = {}
        for visibility in VISIBILITIES:
            scene.radiosity.visibility = visibility
            for oracle in ORACLES:
                start = time.perf_counter()
                image, stats = ca.solve_and_render(scene, oracle, 0.5)
                seconds = time.perf_counter() - start
                renders["%s_%s" % (visibility.lower(), oracle.lower())] = image
                e = image_agreement.compare(image, reference.image, reference.mask)
                rows.append("| %s | %s | %s | %.1f | %d | %d | %+.1f %% | %.1f %% |"
                            % (label, visibility.lower(), oracle.lower(), stats.seconds, stats.elements,
                               stats.links, 100 * e["exposure"], 100 * e["block"]))
                print(rows[-1], "(%.0f s with the render)" % seconds, flush=True)
        if args.images:
            ca.save_pngs(args.images, label, reference, renders)
    in_blender.write_table(args.build, "tessellated_room", rows)


if __name__ == "__main__":
    main()
