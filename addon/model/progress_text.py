"""The running solve's progress in words, for the panel's bar, the status bar
and the console (no bpy).

Elements are leaves, the count the final statistics give; `pass` counts from
0 in the solver's reports and from 1 here.
"""


def progress_fraction(progress):
    return min(max(float(progress.get("fraction", 0.0)), 0.0), 1.0) if progress else 0.0


def duration(seconds):
    """4.2 s, 3:25 or 3:25:45: short enough for the progress bar of a long solve."""
    if seconds < 60:
        return "%.1f s" % seconds
    minutes, secs = divmod(int(seconds), 60)
    return "%d:%02d" % (minutes, secs) if minutes < 60 else "%d:%02d:%02d" % (minutes // 60, minutes % 60, secs)


def progress_texts(progress):
    """The progress bar's text in full ("Pass 3 of 7 · 12,316 elements · 4.2 s") and
    short, without the count ("Pass 3 of 7 · 4.2 s"), and the count ("12,316
    elements", "" before there is one). Elements are leaves, the count the final
    statistics give."""
    if not progress:
        return "Starting", "Starting", ""
    seconds = duration(float(progress.get("seconds", 0.0)))
    passes = progress.get("passes", 0)
    if progress.get("phase") == "linking" or not passes:
        where = "Preparing"
    else:
        # `pass` counts from 0: the pass being refined, or the one just completed.
        where = "Pass {} of {}".format(min(progress.get("pass", 0) + 1, passes), passes)
    leaves = progress.get("leaves", progress.get("elements", 0))
    count = "{:,} elements".format(leaves) if leaves else ""
    return " · ".join(t for t in (where, count, seconds) if t), "%s · %s" % (where, seconds), count


def status_line(progress):
    """One line for the status bar and the console: "Radiosity: 43% · Pass 3 of 7
    · 12,316 elements · 4.2 s"."""
    if not progress:
        return "Radiosity: starting"
    return "Radiosity: {:.0%} · {}".format(progress_fraction(progress), progress_texts(progress)[0])
