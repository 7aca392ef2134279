"""What install_and_solve.py's report must say of the cube it solved and baked,
whichever Blender ran it: tests/blender/test_package.py (Linux Blenders) and
tests/platforms/test_windows.py (Windows Blender under Wine). Needs no bpy.
"""


def check_solved_and_baked(test, report):
    """The solve converged on the cube's 8 result meshes, each with a finite, lit bake."""
    test.assertEqual(report["status"], "Converged")
    test.assertEqual(report["results"], 8)
    test.assertGreater(report["elements"], 8)
    # The baked attribute: radiance on every result mesh, finite, not all dark.
    test.assertEqual(report["attributes"], report["results"])
    test.assertTrue(report["finite"])
    test.assertGreater(report["max_radiance"], 0.1)
    test.assertGreaterEqual(report["min_radiance"], 0.0)
