"""A fake clock for the solver's time budget (solve(clock=...)): its time
passes only as the solve reports progress, so what a budget stops is the
same on an idle machine and on a loaded one."""

import threading


class WorkClock:
    """Seconds that advance by `step` with each progress report of one of
    `phases` (the solve's own measure of the work it has done). Pass the
    object as solve(clock=...), its `progress` as solve(progress=...) and
    `budget` as solve(time_budget=...).

    `late`: the reports of those phases whose work began once the budget
    was spent, which a solve keeping its budget limits to the work in flight
    when it ran out. After `give_up` late reports the clock raises, which
    stops the solve (solve() raises it) instead of letting a solve that
    ignores its budget run on."""

    def __init__(self, budget, step, phases, give_up=100):
        self.budget, self.step, self.phases, self.give_up = budget, step, set(phases), give_up
        self.now = 0.0
        self.reports = []  # (phase, fraction)
        self.late = []
        self._lock = threading.Lock()

    def __call__(self):
        with self._lock:
            return self.now

    def progress(self, report):
        with self._lock:
            if report["phase"] not in self.phases:
                return
            if self.now > self.budget:
                self.late.append((report["phase"], report["fraction"]))
                if len(self.late) > self.give_up:
                    raise RuntimeError("%d reports after the budget ran out: the solve does not keep it"
                                       % len(self.late))
            self.reports.append((report["phase"], report["fraction"]))
            self.now += self.step
