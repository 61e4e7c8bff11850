"""Options and helpers shared by several commands."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from mhtrack import bounds as B
from mhtrack.cli.terminal import show_progress
from mhtrack.names import CLUTTER_FRAMES, DEFAULT_CLUTTER_FRAME


class InputProblem(click.ClickException):
    """A user's input is wrong: one line on stderr, exit status 2 (as a usage error)."""

    exit_code = 2


# ------------------------------------------------------------------ numbers at the edge
#: Bounds of the number options, by option name (docs/errors.md, "Bounds"): (low, high).
#: Every other integer option is within ±2^53 and every other float option finite and
#: within ±1e15; an option's own range (e.g. ``--pd`` in [0, 1]) applies too.
OPTION_BOUNDS: dict[str, tuple[float, float]] = {
    "--seed": (0, B.MAX_SEED),
    "--clutter-rate": (0.0, B.MAX_RATE),
    "--clutter-density": (0.0, B.MAX_DENSITY),
    "--birth-density": (0.0, B.MAX_DENSITY),
    "--cutoff": (0.0, B.MAX_CUTOFF),
    "--match-distance": (0.0, B.MAX_CUTOFF),
    "--order": (1.0, B.MAX_ORDER),
    "--max-age": (0.0, B.MAX_TIME_S),
    "--reorder-window": (0.0, B.MAX_TIME_S),
    "--workers": (1, 1024),
}


class BoundedInt(click.IntRange):
    """An integer in ``[lo, hi]``; the message names the range."""

    def __init__(self, lo: int, hi: int) -> None:
        super().__init__(min=lo, max=hi)
        self.lo, self.hi = lo, hi

    def _describe_range(self) -> str:
        return f"{B.show(self.lo)}<=x<={B.show(self.hi)}"

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> int:
        try:
            v = int(value) if not isinstance(value, str) else int(value.strip(), 10)
        except (TypeError, ValueError):
            v = None
        if isinstance(value, bool) or v is None or not self.lo <= v <= self.hi:
            self.fail(f"{B.clip(repr(str(value)))} is not {B.int_range(self.lo, self.hi)}",
                      param, ctx)
        return v


class BoundedFloat(click.FloatRange):
    """A finite number in ``[lo, hi]`` (``(lo, …`` / ``…, hi)`` when open)."""

    def __init__(self, lo: float, hi: float, lo_open: bool = False,
                 hi_open: bool = False) -> None:
        super().__init__(min=lo, max=hi, min_open=lo_open, max_open=hi_open)
        self.lo, self.hi, self.lo_open, self.hi_open = lo, hi, lo_open, hi_open

    def _describe_range(self) -> str:
        return (f"{B.show(self.lo)}{'<' if self.lo_open else '<='}x"
                f"{'<' if self.hi_open else '<='}{B.show(self.hi)}")

    def _range(self) -> str:
        return (f"{'(' if self.lo_open else '['}{B.show(self.lo)}, {B.show(self.hi)}"
                f"{')' if self.hi_open else ']'}")

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> float:
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            v = float("nan")
        ok = (self.lo < v if self.lo_open else self.lo <= v) and (
            v < self.hi if self.hi_open else v <= self.hi)  # NaN fails both
        if isinstance(value, bool) or not ok:
            self.fail(f"{B.clip(repr(str(value)))} is not a finite number in {self._range()}",
                      param, ctx)
        return v


def _bounded(param: click.Parameter) -> click.ParamType | None:
    """The bounded type of a number option (``None`` for other parameters)."""
    t = param.type
    name = max(getattr(param, "opts", []) or [""], key=len)
    if isinstance(t, BoundedInt | BoundedFloat):
        return None
    if isinstance(t, click.IntRange | click.FloatRange):
        lo, hi = t.min, t.max
        lo_open, hi_open = t.min_open, t.max_open
    elif t in (click.INT, click.FLOAT):
        lo = hi = None
        lo_open = hi_open = False
    else:
        return None
    is_int = isinstance(t, click.types.IntParamType)
    default = (-B.MAX_INDEX, B.MAX_INDEX) if is_int else (-B.MAX_MAGNITUDE, B.MAX_MAGNITUDE)
    blo, bhi = OPTION_BOUNDS.get(name, default)
    if lo is None or lo < blo:
        lo, lo_open = blo, False
    if hi is None or hi > bhi:
        hi, hi_open = bhi, False
    if is_int:
        return BoundedInt(int(lo) + int(lo_open), int(hi) - int(hi_open))
    return BoundedFloat(float(lo), float(hi), lo_open, hi_open)


def bound_number_options(command: click.Command) -> None:
    """Give every number option of ``command`` (and of its subcommands) its bounds
    (:data:`OPTION_BOUNDS`, :mod:`mhtrack.bounds`): a value out of range, NaN or
    infinite is refused with one line naming the option and the range expected."""
    for param in command.params:
        bounded = _bounded(param)
        if bounded is not None:
            param.type = bounded
    for sub in getattr(command, "commands", {}).values():
        bound_number_options(sub)


def out_option(dest: str, former: str, **kw: Any) -> Callable[..., Any]:
    """``--out/-o`` (value in the parameter ``dest``) and the command's former spelling
    ``former`` (e.g. ``--figure``), hidden and kept for a release; ``kw`` as for
    :func:`click.option` (type, help)."""
    def keep(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
        return value if value is not None else ctx.params.get(dest)

    def old(ctx: click.Context, param: click.Parameter, value: Any) -> None:
        if value is not None:
            ctx.params[dest] = value

    def decorate(f: Callable[..., Any]) -> Callable[..., Any]:
        f = click.option(former, f"{dest}_former", hidden=True, expose_value=False,
                         callback=old, type=kw.get("type"))(f)
        return click.option("--out", "-o", dest, callback=keep, default=None, **kw)(f)

    return decorate


def scenario_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``SCENARIO`` (preset name or TOML file) and the common overrides."""
    for opt in reversed(
        [
            click.argument("scenario"),
            click.option("--seed", type=int, default=0, show_default=True,
                         help="Random seed; same seed, same output."),
            click.option("--clutter", type=click.Choice(["uniform", "gmm"]), default=None,
                         help="Replace the scenario's clutter density."),
            click.option("--clutter-rate", type=click.FloatRange(min=0), default=None,
                         help="Mean clutter plots per scan (per sensor)."),
            click.option("--pd", type=click.FloatRange(0, 1, min_open=True), default=None,
                         help="Detection probability of every sensor, in (0, 1]."),
            click.option("--scans", type=click.IntRange(min=1), default=None,
                         help="Number of scans to simulate."),
        ]
    ):
        f = opt(f)
    return f


def clutter_scene_option(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--clutter-scene NAME`` (:data:`mhtrack.scenario.scenes.SCENES`)."""
    return click.option(
        "--clutter-scene", "clutter_scene", default=None, metavar="NAME",
        help="Rotating radars: add a changing clutter scene (weather, coastal, burst, "
             "storm; docs/clutter.md, Clutter scenes), e.g. with radars-clutter.")(f)


def clutter_frame_option(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--clutter-frame`` (:data:`mhtrack.names.CLUTTER_FRAMES`) of ``track`` and
    ``live``."""
    return click.option(
        "--clutter-frame", type=click.Choice(CLUTTER_FRAMES), default=DEFAULT_CLUTTER_FRAME,
        show_default=True, help="Timed plots (live: every plot): estimate each radar's "
        "clutter in the local east-north plane or in the radar's own range and bearing "
        "(docs/clutter.md).")(f)


def attributes_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--attributes/--no-attributes`` and the reply probabilities of a simulation
    (:mod:`mhtrack.scenario.identity`), resolved by :func:`attributes_arg`."""
    for opt in reversed([
        click.option("--attributes/--no-attributes", "attributes", default=None,
                     help="Give the plots secondary-radar attributes: each aircraft's "
                     "address, Mode 3/A code and flight level (the data's own for the "
                     "OpenSky presets), plot types, garbling [on for rotating radars, "
                     "which are secondary radars; off otherwise]."),
        click.option("--psr-only", type=click.FloatRange(0, 1), default=None,
                     help="With attributes: probability of a primary-only detection "
                     "[0.05]."),
        click.option("--ssr-only", type=click.FloatRange(0, 1), default=None,
                     help="With attributes: probability of a secondary-only detection "
                     "[0.1]."),
        click.option("--garble", type=click.FloatRange(0, 1), default=None,
                     help="With attributes: probability of a garbled reply [0.02]."),
    ]):
        f = opt(f)
    return f


def attributes_arg(scenario: Any, attributes: bool | None, psr_only: float | None,
                   ssr_only: float | None, garble: float | None) -> Any:
    """The :class:`~mhtrack.scenario.identity.AttributeOptions` of a simulation of
    ``scenario``, or ``None`` for none: ``attributes`` ``None`` follows
    :func:`~mhtrack.scenario.identity.default_attributes`. A probability given without
    attributes, or probabilities that do not add up, is a usage error."""
    from mhtrack.scenario.identity import AttributeOptions, default_attributes

    given = {k: v for k, v in (("psr_only", psr_only), ("ssr_only", ssr_only),
                               ("garble", garble)) if v is not None}
    on = default_attributes(scenario) if attributes is None else attributes
    if not on:
        if given:
            why = "--no-attributes" if attributes is False else \
                "a scenario without rotating radars (add --attributes)"
            raise click.UsageError(f"--psr-only, --ssr-only and --garble need attributes: "
                                   f"not with {why}")
        return None
    try:
        return AttributeOptions(**given)
    except ValueError as e:
        raise click.UsageError(str(e)) from None


def with_scene_arg(scenario: Any, name: str | None) -> Any:
    """``scenario`` with the clutter scene ``name`` (None: unchanged); a bad name or a
    scenario without rotating radars is a usage error naming ``--clutter-scene``."""
    if name is None:
        return scenario
    from mhtrack.scenario.scenes import with_clutter_scene

    try:
        return with_clutter_scene(scenario, name)
    except ValueError as e:
        raise click.BadParameter(str(e), param_hint="--clutter-scene") from None


def load_scenario_arg(
    scenario: str, clutter: str | None, clutter_rate: float | None, pd: float | None,
    scans: int | None,
) -> Any:
    """A preset by name, or a scenario TOML file, with the command-line overrides."""
    from mhtrack.scenario import PRESETS, apply_overrides, load_scenario, preset

    overrides = {"clutter": clutter, "clutter_rate": clutter_rate, "pd": pd, "scans": scans}
    overrides = {k: v for k, v in overrides.items() if v is not None}
    if scenario in PRESETS:
        return preset(scenario, **overrides)
    path = Path(scenario)
    if path.suffix.lower() == ".toml" or path.exists():
        from mhtrack.io.paths import check_input_file

        if not path.exists():
            raise click.BadParameter(f"no such scenario file: {path}", param_hint="SCENARIO")
        check_input_file(path)
        return apply_overrides(load_scenario(path), **overrides)
    names = ", ".join(sorted(PRESETS))
    raise click.BadParameter(
        f"unknown scenario {scenario!r}: give a preset ({names}) or a .toml file",
        param_hint="SCENARIO",
    )


def echo_json(obj: Any) -> None:
    """Print one JSON object (NaN/inf become null so any JSON parser reads it)."""
    from mhtrack.io.jsonsafe import dumps

    click.echo(dumps(obj))


def table_path(directory: Path, stem: str) -> Path | None:
    """``DIR/stem.csv`` or ``DIR/stem.parquet``, whichever exists."""
    for ext in (".csv", ".parquet"):
        p = directory / f"{stem}{ext}"
        if p.is_file():
            return p
    return None


def executor_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--workers`` / ``--dask-scheduler`` of the Monte-Carlo commands."""
    for opt in reversed(
        [
            click.option("--workers", type=click.IntRange(min=1), default=None,
                         help="Local worker processes [number of CPUs]; 1 runs in this "
                         "process."),
            click.option("--dask-scheduler", default=None, metavar="ADDRESS",
                         help="Run the jobs on this Dask scheduler (e.g. tcp://host:8786) "
                         "instead."),
        ]
    ):
        f = opt(f)
    return f


def executor_kwargs(workers: int | None, dask_scheduler: str | None) -> dict[str, Any]:
    """The ``executor``, ``workers``, ``scheduler`` and ``progress`` keywords of the
    experiment runners, from :func:`executor_options`' values (and
    :func:`~mhtrack.cli.terminal.show_progress`)."""
    if workers is not None and dask_scheduler is not None:
        raise click.UsageError("give --workers or --dask-scheduler, not both")
    if dask_scheduler is not None:
        from mhtrack.experiments.jobs.executor import require_dask

        try:
            require_dask()
        except ImportError as e:
            raise click.ClickException(str(e)) from None
    return {
        "executor": "dask" if dask_scheduler else "local",
        "workers": workers,
        "scheduler": dask_scheduler,
        "progress": show_progress(),
    }


def exit_if_runs_failed(command: str, result: Any) -> None:
    """After a Monte-Carlo study (:class:`~mhtrack.experiments.MonteCarloResult`): name the
    failed runs on stderr and exit with status 1, if any failed or are missing."""
    failed = [(t, i) for t, f in result.failures.items() for i in sorted(f)]
    if failed or result.missing:
        shown = ", ".join(f"{t} run {i}" for t, i in failed[:10])
        more = f" and {len(failed) - 10} more" if len(failed) > 10 else ""
        click.echo(f"mhtrack {command}: {len(failed)} run(s) failed ({shown}{more}); "
                   f"tracebacks in {result.out_dir}/runs/<tracker>/run-<i>.error.txt",
                   err=True)
        click.get_current_context().exit(1)
