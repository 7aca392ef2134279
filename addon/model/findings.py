"""What the solver found in a scene, worded for the user: the one place where
the native module's records (Scene.skipped_faces, repaired_faces and
coincident_faces, stats['reuse_refusal']) and the export's list of what it
left unmodelled become the panel's sentences. No bpy: plain data in, text out.

`face_object(face)` gives the name of the object an input face came from.
"""

# Scene.skipped_faces and repaired_faces: each record's kind, as the user reads it.
FACE_ISSUES = {
    "coincident_corners": "zero area (coincident vertices)",
    "collinear_corners": "zero area (collinear vertices)",
    "crosses_itself": "its outline crosses itself",
    "too_small": "too small to solve",
    "no_triangles": "degenerate after triangulation",
    "repeated_corners": "repeated corners removed",
    "not_planar": "not planar",
}

# stats['reuse_refusal']: why a solve linked anew instead of relighting the one
# kept; none ("") or nothing kept yet (the first solve) is no news.
RELINK_REASONS = {
    "": "",
    "nothing_kept": "",
    "oracle_changed": "the oracle changed",
    "quality_changed": "the quality changed",
    "visibility_changed": "the visibility changed",
    "fixed_bounces": "a fixed number of bounces was asked",
    "smallest_element_changed": "the smallest element changed",
    "linking_changed": "the linking options changed",
    "geometry_changed": "the geometry changed",
    "lights_added_or_removed": "a light was added or removed, or turned on or off",
    "light_changed": "a light moved or changed shape",
    "now_emits": "a surface that did not emit light does",
    "now_reflects": "a black surface now reflects light",
}


def _listed(items, most):
    """'a; b; c' with at most `most` items, then ' and N more'."""
    more = " and %d more" % (len(items) - most) if len(items) > most else ""
    return "; ".join(items[:most]) + more


def _faces(count):
    return "%d face%s" % (count, "s" if count > 1 else "")


def _detail(kind, notes):
    """What the numbers of one kind of note on one object add."""
    if kind == "not_planar":
        triangles = {n["triangles"] for n in notes}
        split = ": split into %d planar triangles" % triangles.pop() if len(triangles) == 1 else \
            ": split into planar triangles"
        bends = [100.0 * n["bend"] for n in notes]
        return split + (" (most: %.3g %%)" % max(bends) if len(bends) > 1 else " (%.3g %%)" % bends[0])
    if kind == "too_small":
        return " (%s%.3g across)" % ("largest " if len(notes) > 1 else "", max(n["size"] for n in notes))
    return ""


def face_notes_message(face_object, notes, what, most=4):
    """One warning line for Scene.skipped_faces or repaired_faces, grouped by
    object and kind and led by `what`, or ''."""
    if not notes:
        return ""
    groups = {}
    for note in notes:
        groups.setdefault((face_object(note["face"]), note["kind"]), []).append(note)
    lines = ["%s: %s %s%s" % (name, _faces(len({n["face"] for n in group})), FACE_ISSUES.get(kind, kind),
                              _detail(kind, group))
             for (name, kind), group in groups.items()]
    return "%s %s" % (what, _listed(lines, most))


def coincident_message(face_object, pairs, most=4):
    """One warning line naming objects whose faces lie in the same place
    (z-fighting in a render; the solver counts each such surface once), or ''."""
    names = []
    for a, b in pairs:
        first, second = face_object(a), face_object(b)
        pair = first if first == second else "%s and %s" % tuple(sorted((first, second)))
        if pair not in names:
            names.append(pair)
    return "faces in the same place, counted once: %s" % _listed(names, most) if names else ""


def unmodelled_message(unmodelled):
    """One warning line for what the solve ignores, or ''."""
    if not unmodelled:
        return ""
    return "Not modelled: " + "; ".join(unmodelled)


def relink_reason(refusal):
    """Why a solve given a kept one linked anew, for the panel ('' when it relit
    or nothing was kept)."""
    return RELINK_REASONS.get(refusal, refusal.replace("_", " "))
