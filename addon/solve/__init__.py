"""Solving: the native module (native.py), a solve from settings to result
without its UI (pipeline.py), and the solve kept for relighting (solve_reuse.py)."""
