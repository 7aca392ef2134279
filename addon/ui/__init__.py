"""The interface: settings (properties.py), operators and the modal solve
(operators.py, live_pacing.py), panels and menus (panels.py), and the 3D views
kept in step with the result (view_sync.py)."""
