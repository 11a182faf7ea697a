"""Figure frames built before they are needed: the figure, its grid of axes and their ticks.

Of the CPU a run figure costs, about a third goes to making its axes and their tick objects
(each tick: three lines and two texts, copied from the axis's first tick), none of which
depends on the data: only on the figure's size and grid.  A *frame* is that part: a
``matplotlib`` figure with its grid of axes made, and major ticks made on each axis.

A builder asks for its frame by *key* (:func:`take`): the arguments that make it, so that a
frame made ahead of time is the frame the builder would make itself; with the key it says how
many ticks its axes will likely show (a hint: more are made as drawn, fewer are not drawn).
:func:`prepare` makes frames of given keys into a pool, :func:`take` hands one out (each once)
or makes it on the spot; :func:`record` finds the keys a set of builders would ask for without
drawing anything.
``testbed run`` uses it to make the frames of a scenario's figures in its drawing process while
the fit runs (:mod:`testbed.reporting.drawer`), from the keys of the scenario's previous run.

A pooled frame is used as it is: the picture is the same as drawn with a frame made on the
spot (tested, byte for byte).  Ticks made beyond those an axis shows are not drawn.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterable
from typing import Any

__all__ = ["TICKS", "Recorded", "clear", "pooled", "prepare", "record", "recording", "take"]

#: Major ticks made ahead on each x and y axis of a prepared frame unless its builder says:
#: the run figures' line plots show 2 to 6 per axis (their locators give only the ticks in
#: view); an axis needing more makes the rest as it draws, one showing fewer leaves the rest
#: undrawn (made for nothing: about 1 ms of CPU each).
TICKS = (6, 5)

_POOL: dict[Hashable, list[Any]] = {}
_RECORDING: list[list[tuple[Hashable, tuple[int, int]]]] = []


class Recorded(Exception):
    """Raised by :func:`take` while recording: the builder's key is noted, it draws nothing."""


def take(key: Hashable, make: Callable[[], Any], ticks: tuple[int, int] = TICKS) -> Any:
    """The frame of ``key``: a prepared one (removed from the pool), else ``make()``.

    ``ticks``: the major ticks (x, y) its axes will likely show, for :func:`prepare`.

    Raises
    ------
    Recorded
        Inside :func:`record`: ``key`` is noted and the builder stops there.
    """
    if _RECORDING:
        _RECORDING[-1].append((key, (int(ticks[0]), int(ticks[1]))))
        raise Recorded
    frames = _POOL.get(key)
    if frames:
        return frames.pop()
    return make()


def recording() -> bool:
    """Whether :func:`record` is running (a builder making its figure itself stops: see it)."""
    return bool(_RECORDING)


def record(builders: Iterable[Callable[[], Any]]) -> list[tuple[Hashable, tuple[int, int]]]:
    """The keys (with tick hints) the ``builders`` ask :func:`take` for, in order; each is
    stopped at its request.

    A builder that asks for none (it makes its figure itself and raises :class:`Recorded`
    when :func:`recording`) or fails before asking adds nothing.
    """
    keys: list[tuple[Hashable, tuple[int, int]]] = []
    _RECORDING.append(keys)
    try:
        for build in builders:
            try:
                build()
            except Recorded:
                pass
            except Exception:  # a builder that cannot run on this input gives no key
                pass
    finally:
        _RECORDING.pop()
    return keys


def prepare(keys: Iterable[tuple[Hashable, tuple[int, int]]], make: Callable[[Hashable], Any],
            style: dict[str, Any] | None = None) -> int:
    """Make the frame of each ``(key, (x ticks, y ticks))`` (as :func:`record` gives them;
    ``make(key)`` returns ``(figure, axes)``) into the pool, with that many major ticks on
    each of its axes, made in ``style`` (the rc parameters the builders draw in); keys already
    in the pool (as often as asked) are not made again.  Returns the number of frames made."""
    import matplotlib as mpl

    n = 0
    have = {k: len(v) for k, v in _POOL.items()}
    with mpl.rc_context(style or {}):
        for key, (nx, ny) in keys:
            if have.get(key, 0) > 0:  # already pooled (e.g. inherited from a server)
                have[key] -= 1
                continue
            frame = make(key)
            for ax in frame[0].axes:
                if nx:
                    ax.xaxis.get_major_ticks(nx)
                if ny:
                    ax.yaxis.get_major_ticks(ny)
            _POOL.setdefault(key, []).append(frame)
            n += 1
    return n


def pooled() -> int:
    """Frames in the pool, not yet taken."""
    return sum(len(v) for v in _POOL.values())


def clear() -> None:
    """Empty the pool."""
    _POOL.clear()
