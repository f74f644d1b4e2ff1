"""The one progress display of every command that computes: a rich bar with the time left on
a terminal (the description cut so that the numbers fit 80 columns); on a log (CI, a file) a
line at every tenth of the work; nothing when told not to log. The work is counted in
whatever the caller advances by (model runs and reference solves, reported from inside the
units a worker runs; or an expected cost), and the time left assumes the rest goes at the
pace so far."""
import sys
import time

from rich.console import Console
from rich.progress import BarColumn, Progress as Bar, TextColumn, TimeElapsedColumn, \
    TimeRemainingColumn

LOG_STEPS = 10     # lines a log gets over the whole work
NUMBERS = 40       # the columns the bar's numbers (percentage, elapsed, time left) need


def shorten(text, width):
    """``text`` cut to ``width`` characters, an ellipsis marking the cut."""
    return text if len(text) <= width else text[:width - 1] + "\u2026"


class Progress:
    """Progress of ``title`` over ``total`` work, as a context manager."""

    def __init__(self, title, total, log=True, width=48):
        self.title, self.total, self.log = title, float(max(total, 1e-300)), log
        self.done, self._said = 0.0, 0
        self.console = Console(stderr=True)
        self.tty = log and sys.stderr.isatty()
        # the numbers keep their room on a narrow terminal: the description gives way
        self.width = max(12, min(width, self.console.width - NUMBERS))
        self._bar = Bar(TextColumn(f"{{task.description:<{self.width}}}"),
                        BarColumn(bar_width=None if self.console.width > 100 else 10),
                        TextColumn("{task.percentage:>3.0f}%"), TimeElapsedColumn(),
                        TextColumn("left"), TimeRemainingColumn(), console=self.console,
                        disable=not self.tty)

    def __enter__(self):
        self.t0 = time.perf_counter()
        self._bar.__enter__()
        self._task = self._bar.add_task(self.title, total=self.total)
        return self

    def __exit__(self, *exc):
        return self._bar.__exit__(*exc)

    def advance(self, work=0.0, text=None):
        """``work`` more done; ``text`` what is being done now."""
        self.done += work
        self._bar.update(self._task, completed=self.done,
                         description=shorten(text if text is not None else self.title, self.width))
        step = int(LOG_STEPS * self.done / self.total)
        if self.log and not self.tty and work and step > self._said:
            self._said = step
            spent = time.perf_counter() - self.t0
            left = spent * (self.total - self.done) / max(self.done, 1e-300)
            self.say(f"{self.title}: {self.done / self.total:.0%} after {spent:.0f} s, "
                     f"about {left:.0f} s left")

    def say(self, text):
        """A line above the bar (or in the log)."""
        if self.log:
            self.console.print(text, highlight=False)


__all__ = ["Progress"]
