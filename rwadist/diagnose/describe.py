"""The open world of ``rwadist diagnose`` (issue 33, item 3): what the residual holds above the noise that no effect
class explains is described (:class:`~rwadist.diagnose.unexplained.Unexplained`), never dropped and never forced
into a class.

Two steps around the search (:func:`rwadist.diagnose.search.diagnose`):

- :func:`start`, before it: lines at one fixed frequency in every run are found in the data and taken out of the
  records the search reads (:mod:`~rwadist.diagnose.fixed_lines`: left in, they were fitted as a test-stand
  resonance that spoilt the wheel's modes);
- :func:`finish`, after it: the error metric (and the narrow-line metric) measured on the data as given, and the
  residual of the final model described by signature (the detectors of :mod:`~rwadist.diagnose.describe_lines` and
  :mod:`~rwadist.diagnose.describe_structure`), each description with its share of the misplaced power left.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial

import numpy as np

from . import take_back
from .describe_reach import TRACK_SHARE_FLOOR, lifted_hold, on_a_moving_skirt, with_track_causes, without_notched_lines
from .engine import Context
from .fixed_lines import describe_fixed_lines, find_fixed_lines, remove_fixed_lines, subtract_tones
from .one_channel_lines import describe_one_channel_lines, find_one_channel_lines, one_channel_line_shares
from .range_lines import describe_range_lines, find_range_lines, range_line_shares, range_line_tones
from .run_order import read_in_recorded_order as in_order
from .state import State
from .take_back import on_a_moving_track, with_groups, without_taken_back


@dataclass
class Opened:
    """What :func:`start` found: ``ctx`` the context the search reads (the data with the fixed lines taken out, or
    the data as given), ``raw`` the context of the data as given, ``fixed`` the fixed lines
    (:class:`~rwadist.diagnose.fixed_lines.FixedLine`), ``copies`` the channel copies
    (:class:`~rwadist.diagnose.channel_copy.ChannelCopy`)."""

    ctx: Context
    raw: Context
    fixed: list = field(default_factory=list)
    copies: list = field(default_factory=list)
    #: run index -> dB: the common factor of those runs taken out of the records the search reads (:func:`run_steps`;
    #: NaN: a run whose change was not read, left out of them)
    steps: dict = field(default_factory=dict)
    #: when ``ctx`` lacks runs (steps of NaN): the context of the records the search reads with every run, on which
    #: the final model's residual is described (its runs are the data's); else None
    whole: Context | None = None
    #: the fixed lines' sidebands taken out with them (:class:`~rwadist.diagnose.describe_carrier.Sideband`)
    sidebands: list = field(default_factory=list)
    #: lines at a constant ratio of the speed on one channel of the radial-force pair that the wheel's translation mode
    #: does not lift, taken out (:class:`~rwadist.diagnose.one_channel_lines.OneChannelLine`)
    one_channel: list = field(default_factory=list)
    #: lines on the radial-force pair over one band of speeds that the translation mode does not lift, taken out
    #: (:class:`~rwadist.diagnose.range_lines.RangeLine`)
    ranged: list = field(default_factory=list)


def start(ctx: Context, steps: dict | None = None) -> Opened:
    """The context the search reads: ``ctx`` itself, or, when the data hold lines at one fixed frequency in every run
    (:func:`~rwadist.diagnose.fixed_lines.find_fixed_lines`) or a channel carrying a copy of another's content
    (:func:`~rwadist.diagnose.channel_copy.find_channel_copies`, looked for once the fixed lines, common to every
    channel, are out), a context of the same settings on the records with those taken out.  ``steps`` (run index ->
    dB, from a first search's :func:`run_steps`): those runs' records also divided by their common factor, and the
    runs of a NaN step (their change not read) left out of the search's context (``Opened.whole`` keeps them)."""
    from .channel_copy import find_channel_copies, remove_channel_copies
    from .describe_carrier import find_sidebands

    fixed = find_fixed_lines(ctx)
    sidebands = find_sidebands(ctx, fixed) if fixed else []
    test = remove_fixed_lines(ctx, fixed + sidebands) if fixed else ctx.test
    copies = find_channel_copies(ctx, test)
    if copies:
        test = remove_channel_copies(test, copies)
    on = getattr(steps, "channels", None)
    steps = dict(steps or {})
    if steps and test is not None:
        test = scale_runs(test, {r: dB for r, dB in steps.items() if np.isfinite(dB)}, on)
    from ..spectra import compute_spectra

    def context(test):
        sp = compute_spectra(test, nperseg=ctx.sp.nperseg, window=ctx.sp.window, f_lim=ctx.sp.f_lim)
        return Context(sp, ctx.channels, test)

    # a line of one radial-force channel that the wheel's translation mode does not lift: a source outside the wheel
    # (:mod:`.one_channel_lines`), read once the fixed lines and copies are out; left in, the empirical base made it a
    # planar radial-force line (both channels) and the modes' fit carried it through the translation mode
    # (and a line on the pair over one band of speeds, not lifted either: :mod:`.range_lines`; one empirical fit)
    from .one_channel_lines import one_channel_tones, pair_fit

    read = ctx if test is ctx.test else context(test)
    fit = pair_fit(read)
    ones = find_one_channel_lines(read, fit) if fit is not None else []
    ranged = find_range_lines(read, fit, ones) if fit is not None else []
    if ones or ranged:
        test = subtract_tones(read.test, one_channel_tones(ones) + range_line_tones(ranged))
    if not fixed and not copies and not steps and not ones and not ranged:
        return Opened(ctx, ctx)
    whole = read if not ones and not ranged and read is not ctx else context(test)
    unread = {r for r, dB in steps.items() if not np.isfinite(dB)}
    if not unread or test is None:
        return Opened(whole, ctx, fixed, copies, steps, sidebands=sidebands, one_channel=ones, ranged=ranged)
    from ..data import SteadyTest

    kept = SteadyTest([run for i, run in enumerate(test.runs) if i not in unread], dict(test.meta))
    return Opened(context(kept), ctx, fixed, copies, steps, whole, sidebands=sidebands, one_channel=ones, ranged=ranged)


class RunSteps(dict):
    """Run index -> dB of a run-to-run change (:func:`run_steps`), and ``channels``: those it was read on (None: every
    channel; a drift of the force bridges alone is no change of the torques)."""

    def __init__(self, steps=(), channels: tuple | None = None):
        super().__init__(steps)
        self.channels = channels


def scale_runs(test, steps: dict, channels: tuple | None = None):
    """A copy of ``test`` with the records of each run r of ``steps`` multiplied by 10^(−steps[r]/20) (the run's
    common factor, a power ratio in dB, taken out) on ``channels`` (None: every channel); new arrays, the input
    unchanged."""
    from dataclasses import replace

    from ..data import SteadyTest

    runs = [replace(run, signals={c: x * 10.0 ** (-steps[i] / 20.0) if channels is None or c in channels else x
                                  for c, x in run.signals.items()})
            if i in steps else run for i, run in enumerate(test.runs)]
    return SteadyTest(runs, dict(test.meta))


#: :func:`search_standing` of a search that located every suspension mode and added nothing: none stands higher
BEST_STANDING = (3, 0)


def search_standing(diag) -> tuple:
    """(the number of the wheel's suspension modes the model locates, minus the number of effects added beyond the
    base): what a search run again with a run change taken out must improve on (:func:`run_steps`), compared as a
    tuple.  A mode the fit declares ``unconstrained`` is not located: left in the records, a changed run's lines are
    missed by the modes' linear model by more than its misfit bound (family wheel 0, every third run 3.5 dB up: the
    translation and rocking declared, the rocking's kept value 1760 Hz, truth 95 Hz).  The parts of one effect of
    several parts (a floor law of several channels, one hypothesis: ``Hypothesis.group``) count as one effect."""
    added = [h for h in diag.hypotheses if h.passed and not h.base_line and h.effect.kind != "suspension_modes"]
    modes = [e for e in diag.state_after.effects if getattr(e, "kind", "") == "suspension_modes"]
    located = sum(3 - len(getattr(e, "unconstrained", ())) for e in modes)
    whole = {id(h) if getattr(h, "group", None) is None else id(h.group) for h in added}
    return (located, -len(whole))


#: The runs whose change was not read are left out of the second search only when they are at most this fraction of
#: the runs (the change read on the others).
RUN_UNREAD_FRACTION = 0.5


def run_steps(diag, every_run: bool = True) -> RunSteps:
    """Run index -> dB: the runs a ``run_change`` record of ``diag`` holds apart from the others (a few runs changed
    by a common factor: a re-mounting, a range switch) and their offsets, when the search may have been led by them:
    it added an effect beyond its base, or, on the default path (no model given), did not locate each of the wheel's
    ``suspension_modes`` (left in the records, a changed run's lines were fitted as a test-stand resonance of gain
    7.5 or an amplitude law Ω^1.4, and the modes were not located, on two wheels of the family with every third run
    3.5 dB up).  A run whose change could not be read (``runs_not_read``) gets NaN: left out of the second search.
    A change spread over every run (a drift) gives every run read its factor (``run_gains_dB``) with ``every_run``,
    the runs held apart otherwise.  Empty otherwise, or without the time series."""
    ctx = diag.ctx
    if ctx.test is None:
        return RunSteps()
    recs = [u for u in diag.unexplained if u.signature == "run_change"]
    if not recs:
        return RunSteps()
    located, minus_added = search_standing(diag)
    if not minus_added and (located == 3 or diag.model_given):
        return RunSteps()
    index = {name: i for i, name in enumerate(ctx.sp.run_names)}
    p = recs[0].parameters
    # a drift spread over every run is taken out of every run, each by its factor against the model's lines
    # (:mod:`.run_gains`): the few runs beyond the scatter alone leave the rest of it bending the lines' course
    every = every_run and p.get("pattern") == "spread" and p.get("run_gains_dB")
    named, offsets = ((p["run_gain_runs"], p["run_gains_dB"]) if every
                      else (p.get("runs", ()), p.get("run_offsets_dB", ())))
    steps = {index[n]: float(dB) for n, dB in zip(named, offsets) if n in index and np.isfinite(dB)}
    # a run whose change could not be read (too few lines over the noise: the lowest speeds) may be a changed one: its
    # factor unknown, it is left out of the second search (NaN), when the change was read on most runs (family wheel
    # 2, 300-3000 rpm, every third run 3.5 dB up: the 442-rpm run, switched and unread, pulled the rocking whirl to
    # I_zz/I_rr 2.5 and an amplitude law Ω^2.16 was added; without the four unread runs: 50.3 Hz, 2.18, nothing added)
    unread = [index[n] for n in p.get("runs_not_read", ()) if n in index]
    if steps and len(unread) <= RUN_UNREAD_FRACTION * ctx.runs.size:
        steps.update({r: float("nan") for r in unread})
    return RunSteps(steps, tuple(recs[0].channels))


@dataclass
class Residual:
    """The residual of ``state`` on ``ctx`` in the error metric's bands: per channel the misplaced power ``e``
    (max(|D − M| − 2σ, 0), divided by the unit group's scale), the data's and the model's band powers ``D``, ``M``
    (runs × bands, every run of the context), and ``total`` = Σ e (the metric's numerator)."""

    ctx: Context
    state: State
    e: dict
    D: dict
    M: dict
    total: float

    @staticmethod
    def of(ctx: Context, state: State) -> "Residual":
        from .constants import NOISE_Z

        _, _, parts = ctx.run_errors(state, ctx.runs, detail=True)
        e, D, M = {}, {}, {}
        for c, (resid, sig) in parts.items():
            scale = ctx.scale(c)
            e[c] = np.maximum(np.abs(resid) - NOISE_Z * sig, 0.0)
            D[c] = ctx._data_bands(state, c, ctx.runs)[1]
            M[c] = D[c] - resid * scale
        total = float(sum(np.nansum(x) for x in e.values()))
        return Residual(ctx, state, e, D, M, total)

    def band_of(self, f_hz) -> np.ndarray:
        """Band index (clipped to the bands) of frequencies ``f_hz`` (Hz, any shape)."""
        from .constants import BAND_BINS

        k = np.rint(np.asarray(f_hz, dtype=float) / self.ctx.df).astype(int)
        return np.clip((k - self.ctx.k_lo) // BAND_BINS, 0, self.ctx.n_bands - 1)

    def measure(self, cells: dict) -> tuple:
        """(share of the misplaced power, median level 10·log10(D/M) dB) over ``cells`` (channel -> bool mask (runs,
        bands) over the context's runs)."""
        got, levels = 0.0, []
        for c, mask in cells.items():
            if c not in self.e or not np.any(mask):
                continue
            got += float(np.nansum(self.e[c][mask]))
            with np.errstate(divide="ignore", invalid="ignore"):
                levels.append(10 * np.log10(self.D[c][mask] / self.M[c][mask]))
        lv = np.concatenate(levels) if levels else np.empty(0)
        lv = lv[np.isfinite(lv)]
        return got / self.total if self.total > 0 else 0.0, float(np.median(lv)) if lv.size else float("nan")

    def mask(self, c: str) -> np.ndarray:
        return np.zeros(self.e[c].shape, bool)


def fixed_line_shares(res: Residual, lines) -> dict:
    """Line index -> (share, level dB) of each fixed line on the data as given: the cells of its band in the runs
    where it is lit, in the channels that carry it."""
    pos = {int(r): i for i, r in enumerate(res.ctx.runs)}
    out = {}
    for i, ln in enumerate(lines):
        b = int(res.band_of(ln.f_Hz))
        cells = {}
        for c in ln.channels:
            if c not in res.e:
                continue
            m = res.mask(c)
            m[[pos[r] for r in ln.runs if r in pos], b] = True
            cells[c] = m
        out[i] = res.measure(cells)
    return out


def channel_copy_shares(res: Residual, copies) -> dict:
    """Copy index -> (share, level dB) of each channel copy on the data as given: the target's bands where the copy,
    |κ|² × the source's band power, is at least a tenth of the target's own."""
    out = {}
    for i, cp in enumerate(copies):
        if cp.target not in res.e or cp.source not in res.D:
            continue
        out[i] = res.measure({cp.target: abs(cp.kappa) ** 2 * res.D[cp.source] >= 0.1 * res.D[cp.target]})
    return out


def line_causes(diag, bearings=(), extra_h=()) -> list:
    """Candidate physical causes of the improved model's lines: bearing ratios (:func:`rwadist.bearings.line_causes`)
    for a line whose ratio h is not a whole number (within twice the resolution, :func:`ratio_resolution`), a motor's
    torque ripple (:func:`rwadist.motor.motor_causes`) for an axial-torque line at a whole h ≥ 2: [{"direction", "h",
    "source", "causes"}] for those with at least one, each (direction, h) once; ``source`` is "effect" for a line a ``missing_harmonic`` added, "base"
    for a line of a base fitted from the data, "model" for one of the given model.  ``extra_h``: ratios of lines
    described but not in the model (the relations among lines read them too)."""
    from ..bearings import line_causes as causes_of
    from ..model import DIRECTIONS
    from ..motor import motor_causes
    from ..sideband_causes import sideband_causes, signed_lines
    from .describe_lines import ratio_resolution

    res = ratio_resolution(diag.ctx)
    added = {(getattr(h.effect, "direction", None), round(float(getattr(h.effect, "h", np.nan)), 3))
             for h in diag.hypotheses if h.passed and not h.base_line}
    fitted = not diag.model_given or diag.state_after.base != diag.state_before.base
    # a line an effect names (a sideband pair's) has that effect for its cause: read by the others, given none
    named = {(d, round(float(h), 3)) for e in diag.model.typed_effects()
             for d, h in getattr(e, "named_lines", tuple)()}
    lines = [(d, float(x.h)) for d in DIRECTIONS for x in diag.model.harmonics(d)]
    signed = {d: signed_lines(d, diag.model.harmonics(d)) for d in DIRECTIONS}
    # a line's sense, one per (direction, h): None where it has a co- and a counter-rotating part
    parts: dict = {}
    for d in DIRECTIONS:
        for x in diag.model.harmonics(d):
            parts.setdefault((d, float(x.h)), []).append(getattr(x, "sense", None))
    sense = {k: v[0] if len(v) == 1 else None for k, v in parts.items()}
    every = sorted({h for _, h in lines} | {float(h) for h in extra_h})
    out = []
    seen = set()
    for d, h in lines:
        # a line with a co- and a counter-rotating part is two harmonics at one h: one line, named once
        if (d, h) in seen or (d, round(h, 3)) in named:
            continue
        seen.add((d, h))
        # one of two sidebands of a stronger line (a modulation of it), whatever else it may be
        got = sideband_causes(d, h, sense.get((d, h)), signed[d], res)
        if abs(h - round(h)) <= 2 * res:
            got += motor_causes(h, res, d)          # a whole multiple: no bearing ratio, a motor's ripple on Tz
        else:
            # the lines of its direction stronger than it: what it may be a sum or difference of
            level = {float(x.h): abs(float(x.C)) for x in diag.model.harmonics(d) if getattr(x, "C", None) is not None}
            parents = [o for o, c in level.items() if c > level.get(h, np.inf)]
            got += causes_of(h, res, bearings, [o for o in every if abs(o - h) > res], parents)
        if got:
            src = "effect" if (d, round(h, 3)) in added else ("base" if fitted else "model")
            out.append({"direction": d, "h": h, "source": src, "causes": got})
    return out


#: Effect kinds whose state already holds the noise floor of the torques as a load-cell correction reads them.
_CORRECTED_FLOOR_KINDS = ("lever_arm_noise",)


def floor_as_read(ctx: Context, state: State) -> State:
    """``state``, or a copy whose torque channels' instrument noise N_c(f) (unit²/Hz) is re-estimated
    (:func:`rwadist.diagnose.engine.noise_estimate`) from the data as the state reads them, when it reads them corrected
    for a load-cell offset (T − r × F, a ``cross_coupling``) with the noise of the data as given: the detectors of the
    open world compare the corrected data with the model, and the correction moves the force sensors' noise into the
    torques (r × n_F; the ``lever_arm_noise`` class fits that transfer, and a state holding it is returned as it is).
    Read against the floor of the uncorrected torques, trial13's clean data (r = 25 mm, torque floor +1 dB corrected;
    the class's held-out gain negative) lit bins at the χ² level in every run, and the ridge test read them as 4-38
    ``speed_line`` records at h 0.26-0.81 in Tx Ty that the data do not hold (none with r = 0).  A channel with a floor
    law (``broadband_floor``) keeps its noise: the law holds the rest of its floor."""
    from .constants import TORQUE_CHANNELS
    from .engine import noise_estimate
    from .reduce import column_nanmedian

    if state.load_cell_offset is None or any(getattr(e, "kind", None) in _CORRECTED_FLOOR_KINDS
                                             for e in state.effects):
        return state
    chans = [c for c in TORQUE_CHANNELS if c in ctx.channels and c not in state.floors]
    if not chans:
        return state
    # as the search's own start (:func:`rwadist.diagnose.engine.initial_state`): the median block floor of the data
    # as read, refined between the band centres; outside them (the lowest bins) that median, not the uncorrected one
    out = state.copy()
    out.noise = dict(state.noise, **{c: column_nanmedian(ctx.data_floor(state, c)[ctx.runs]) for c in chans})
    fresh = noise_estimate(ctx, out)
    out = state.copy()
    out.noise = dict(state.noise, **{c: fresh[c] for c in chans})
    return out


def describe_residual(searched: Residual, bearings=(), res: Residual | None = None, changes: bool = False,
                      carriers=(), known_sidebands=()) -> list:
    """The records of the final model's residual on ``searched`` (the detectors of the describe_* modules), each with
    its share of the misplaced power and its level measured on ``res`` (default ``searched``: the same runs and bands).
    ``changes``: the run-to-run change read on ``res`` (the data as given: the records the search read had the changed
    runs' factor taken out, :func:`run_steps`).  ``carriers``: the fixed lines found before the search
    (:mod:`.describe_carrier` reads their sidebands), ``known_sidebands`` the sidebands taken out with them."""
    from . import describe_structure as structure
    from .describe_affine import affine_lines, with_affine_lines
    from .describe_blend import blended_lines
    from .describe_carrier import measure_track, on_a_sideband, sideband_lines, sideband_tracks
    from .describe_drift import with_drifts
    from .describe_filter import frequency_response
    from .describe_fixed import fixed_lines_in_part
    from .describe_gain import as_recorded
    from .describe_hump import broadband_hump, humps_in_some_runs
    from .describe_line_step import line_steps, with_line_steps, without_steps
    from .describe_lines import speed_lines
    from .describe_mode_drift import drifting_modes
    from .describe_partial import partial_lines
    from .describe_pooled import moving_resonances
    from .describe_split import radial_pairs
    from .describe_trend import gain_trend

    res = searched if res is None else res
    ctx, state = searched.ctx, floor_as_read(searched.ctx, searched.state)
    pos = {int(r): i for i, r in enumerate(ctx.runs)}
    spin = ctx.omega[ctx.runs] / (2 * np.pi)

    def of_runs(runs):
        return res.measure({c: np.isin(ctx.runs, runs)[:, None] & np.ones(res.e[c].shape, bool) for c in res.e})

    def of_band_runs(chans, f0, f1, runs):        # the bands of [f0, f1] in ``runs``
        b0, b1 = int(res.band_of(f0)), int(res.band_of(f1))
        rows = np.isin(ctx.runs, runs)
        cells = {c: res.mask(c) for c in chans if c in res.e}
        for m in cells.values():
            m[rows, b0:b1 + 1] = True
        return res.measure(cells)

    def of_track(chans, track, zeta):
        f = track(spin)
        lo, hi = res.band_of(f * (1 - 3 * zeta)), res.band_of(f * (1 + 3 * zeta))
        cells = {c: res.mask(c) for c in chans if c in res.e}
        for m in cells.values():
            for i in range(spin.size):
                m[i, lo[i]:hi[i] + 1] = True
        return res.measure(cells)

    def of_line(chans, h, runs):          # h: one ratio, or several (every line of a channel's gain)
        cells = {c: res.mask(c) for c in chans if c in res.e}
        for m in cells.values():
            for r in runs:
                m[pos[int(r)], res.band_of(np.asarray(h) * ctx.omega[int(r)] / (2 * np.pi))] = True
        return res.measure(cells)

    of_track_f = partial(measure_track, res)        # (chans, one frequency per run of ``runs``, runs)

    def of_band(chans, f0, f1):
        return of_band_runs(chans, f0, f1, ctx.runs)

    def of_fixed(chans, f_hz, runs):
        return of_band_runs(chans, f_hz, f_hz, runs)

    ratios = structure.line_ratios(ctx, state)
    others = [x.h for d in ("radial_force", "radial_torque", "axial_force", "axial_torque")
              for x in state.model.harmonics(d)]
    # a narrow hump on a fixed line taken out before the search is its leftover lobe (trial 30: mains in Fz)
    out = [u for u in broadband_hump(ctx, state, of_band) if not on_a_fixed_line(u, carriers, float(ctx.sp.df))]
    out += humps_in_some_runs(ctx, state, of_band_runs, out)
    # a moving resonance: read on steady lines resolved from their neighbours, described where its cells hold content
    steady = [without_steps(ctx, structure.steady_lines(structure.resolved_lines(ctx, state, r), float(ctx.df)))
              for r in ratios]
    # the model's own mode moving over the runs first: a resonance lifting lines fits only its rise
    drifting = [u for u in drifting_modes(ctx, state, steady, of_track) if holds_content(u, res)]
    out += drifting + moving_resonances(ctx, state, steady, of_track, lambda u: holds_content(u, res), drifting)
    read = structure.line_ratios(res.ctx, res.state) if changes else ratios
    out += _run_change(ctx, state, read, of_runs, in_order, changes)
    out += speed_lines(ctx, state, of_line, bearings, others, ctx.left_out)
    out += partial_lines(ctx, state, structure.line_ratios(ctx, state, absent=True), of_line)
    sidebands = sideband_lines(ctx, state, carriers, of_track_f, known_sidebands)
    tracks = sideband_tracks(sidebands, known_sidebands)
    out += [u for u in fixed_lines_in_part(ctx, state, of_fixed) if not on_a_sideband(ctx, u, tracks)] + sidebands
    # a radial pair's channels reading the lines differently: a gain of one (on the recorded channels), two translation
    # modes (a support stiffer along one axis), a resonance of one channel (a sensor's, a fixture's along one axis),
    # one channel recorded later than the other (its lines' x/y phase off a quarter turn ∝ f)
    out += radial_pairs(ctx, as_recorded(searched.state), state, of_line)
    # one line's level stepping between runs, the others not
    out = with_line_steps(out, line_steps(ctx, state, ratios, of_line, out))
    # a model line that is two or more lines closer than the Welch segments resolve (the whole record reads it alone)
    out += blended_lines(ctx, state, of_line)
    # a gain common to the channels that changes with speed, on the recorded channels too; one of the line's frequency
    out += gain_trend(ctx, recorded := as_recorded(searched.state), of_line) + frequency_response(ctx, recorded, of_line)
    # a line whose ratio drifts with the speed (a cage slipping), what its fixed-ratio model line made of it; a line on
    # a straight track f0 + b·f_spin off both axes, whose pieces the detectors above described; a moving resonance
    # made of a narrow line's leakage into the model's lines it passes is that line's
    out = with_affine_lines(ctx, state, with_drifts(ctx, state, out, of_line), affine_lines(ctx, state, of_track_f,
                                                                                             carriers))
    # a line the track's antiresonance takes down is no source that stops
    return without_notched_lines(structure.without_line_leaks(out, float(ctx.df)))


def _run_change(ctx, state, read: list, of_runs, in_order, taken_out: bool) -> list:
    """The ``run_change`` records of the lines' ratios ``read`` (:func:`.describe_structure.run_change`, annotated by
    :func:`.run_gains.annotate`): whether the runs changed is read on every direction's lines, where and by how much
    on the directions that follow the change (:func:`.run_gains.in_changed_directions`; a drift of the force bridges
    alone, read over every line at −1.22 dB for −1.5).  Read on one direction's lines from the start, a line's own
    scatter (family wheel 2's speed sidebands beating in the radial force) was taken for a change of the runs."""
    from . import describe_structure as structure
    from .run_gains import annotate, in_changed_directions

    got = structure.run_change(ctx, read, of_runs, in_order(ctx, read))
    where = in_changed_directions(ctx, read) if got else read
    if len(where) < len(read):
        there = structure.run_change(ctx, where, of_runs, in_order(ctx, where))
        if there:
            got, read = there, where
    return annotate(ctx, state, got, read, taken_out=taken_out)


#: A hump at most this many bins wide whose peak lies within its own width of a fixed line on one of its channels is
#: that line's main lobe (:func:`on_a_fixed_line`): a Hann lobe spans 4 bins, the floor's 3-bin mean widens it by 2
LINE_LOBE_BINS = 8


def on_a_fixed_line(hump, fixed, df: float) -> bool:
    """True when the ``broadband_hump`` record ``hump`` is at most :data:`LINE_LOBE_BINS` bins of ``df`` (Hz) wide and
    peaks within that width of a line of ``fixed`` (:class:`~rwadist.diagnose.fixed_lines.FixedLine`) on one of its
    channels."""
    width = hump.f_Hz[1] - hump.f_Hz[0]
    return width <= LINE_LOBE_BINS * df and any(
        set(hump.channels) & set(ln.channels) and abs(hump.parameters["peak_Hz"] - ln.f_Hz) <= max(width, 2 * df)
        for ln in fixed)


def _described(diag, opened: Opened, search_after: State, bearings=()) -> tuple:
    """(records, the residual on the data as given) of the search's final state ``search_after`` (on ``opened.ctx``):
    ``diag``'s context, final state (a copy on the data as given when those differ: its cached error terms were the
    cleaned data's), error after and narrow-line error after set to those of the data as given."""
    searched = (Residual.of(opened.whole, search_after.copy()) if opened.whole is not None else
                Residual.of(opened.ctx, search_after) if opened.ctx is not opened.raw else None)
    after = search_after.copy() if searched is not None else search_after
    # the figures of merit and the waterfall read the torques against their floor as the final model reads them: a
    # load-cell offset's correction T − r × F carries the forces' noise into them (trial16's 30 mm offset, exact:
    # the torques 1.3 dB over the model's floor in every band, the narrow-line error 78-163× the clean level)
    read = floor_as_read(opened.raw, after)
    # the context the search read, for the records of what it was set to do (modes_status: whether the wheel's modes
    # were to be fitted, read on the data the search read; the W7 trial's pickup case wrote suspension_modes_status null)
    from .modes_status import SEARCH_CONTEXT

    opened.raw._memo[SEARCH_CONTEXT] = opened.ctx
    diag.ctx, diag.state_after = opened.raw, read
    diag.error_after, diag.rms_error_after = opened.raw.error(read), opened.raw.rms_error(read)
    diag.contrast_error_after = opened.raw.contrast_error(read)
    res = Residual.of(opened.raw, after)
    from .channel_copy import describe_channel_copies
    from .describe_carrier import describe_sidebands

    found = describe_fixed_lines(opened.raw, opened.fixed, fixed_line_shares(res, opened.fixed))
    found += describe_sidebands(res, opened.sidebands)
    found += describe_one_channel_lines(opened.raw, opened.one_channel, one_channel_line_shares(res, opened.one_channel))
    found += describe_range_lines(opened.raw, opened.ranged, range_line_shares(res, opened.ranged))
    found += describe_channel_copies(opened.raw, opened.copies, channel_copy_shares(res, opened.copies))
    # the final model's residual on the data the search read (the fixed lines and copies out), shares on the data
    found += describe_residual(searched or res, bearings, res, changes=bool(opened.steps), carriers=opened.fixed,
                               known_sidebands=opened.sidebands)
    from .describe_law import describe_laws

    found += describe_laws(res, getattr(diag, "laws_below_gain", ()))
    # a law a described moving resonance's shape makes is said so first
    return with_track_causes(found), res


def cells_of(u, res: Residual) -> dict:
    """The waterfall cells (channel -> bool mask (runs, bands)) a record covers, in its channels and the runs within
    its speed range: a ``speed_line`` the band of f = h·Ω/2π in each run (and its neighbours), a ``partial_line``
    that band alone, a
    ``moving_resonance`` the bands of its track ±3ζ, a ``channel_copy`` the target's bands where the copy is at
    least a tenth of the target's power, the others the bands of their frequency range; a ``run_change`` none (it is
    a change of whole runs: a class gaining in those runs is not fitted to it), nor a ``line_property`` (a property of
    every line of a channel, a gain: a class acting on that channel's lines is not fitted to it), but for a gain
    that changes with speed (``gain_trend``) the bands of its lines in its channels: an amplitude law on one of them
    is that trend read on one line (trial16 tempgain at seed 2: Ω^1.93 on one of 25 lines that share it), and for a
    line whose ratio drifts (``ratio_drift``) the bands between the model's line and the data's (:func:`_drift_cells`)."""
    if u.signature == "line_property" and u.parameters.get("property") in ("gain_trend", "frequency_response"):
        return _trend_cells(u, res)
    if u.signature == "line_property" and u.parameters.get("property") == "ratio_drift":
        return _drift_cells(u, res)
    if u.signature in ("run_change", "line_property"):
        return {}
    ctx = res.ctx
    rpm = ctx.omega[ctx.runs] * 60.0 / (2 * np.pi)
    runs = (rpm >= u.speed_rpm[0] - 1e-6) & (rpm <= u.speed_rpm[1] + 1e-6)
    spin = rpm / 60.0
    p = u.parameters
    if u.signature == "broadband_hump" and p.get("run_speeds_rpm"):      # a hump in some runs: those runs only
        runs &= np.any(np.abs(rpm[:, None] - np.asarray(p["run_speeds_rpm"], float)[None, :]) <= 1e-6 * np.abs(rpm).max(),
                       axis=1)
    rows = np.flatnonzero(runs)
    if u.signature == "channel_copy":
        src, dst = p.get("source"), p.get("target")
        if src not in res.D or dst not in res.e:
            return {}
        return {dst: float(p.get("gain", 0.0)) ** 2 * res.D[src] >= 0.1 * res.D[dst]}
    if u.signature in ("speed_line", "partial_line") and u.h is not None:
        b = res.band_of(u.h * spin[rows])
        # a partial line is a line of the model: its own band only (with the bands either side, a true law on a
        # neighbour 0.6·Ω/2π away was taken back with it)
        lo, hi = (b, b) if u.signature == "partial_line" else (np.maximum(b - 1, 0), np.minimum(b + 1, ctx.n_bands - 1))
    elif u.signature == "sideband_line" and "carrier_Hz" in p:
        # each side's band in every run of the range (a side below 0 Hz or past the band clips to an edge band: kept,
        # as a speed line's)
        sides = np.asarray(p.get("sides", [1]), float)
        rows = np.repeat(rows, sides.size)
        f = np.abs(p["carrier_Hz"] + np.tile(sides, rows.size // max(sides.size, 1)) * p["h"] * spin[rows])
        lo = hi = res.band_of(f)
    elif u.signature == "affine_line" and "offset_Hz" in p:
        b = res.band_of(p["offset_Hz"] + p["slope"] * spin[rows])
        lo, hi = np.maximum(b - 1, 0), np.minimum(b + 1, ctx.n_bands - 1)
    elif u.signature == "moving_resonance" and "slope_Hz_per_Hz_of_spin" in p:
        f_lo, f_hi = p["f_at_lowest_speed_Hz"], p["f_at_highest_speed_Hz"]
        s_lo, s_hi = u.speed_rpm[0] / 60.0, u.speed_rpm[1] / 60.0
        f = f_lo + (f_hi - f_lo) * (spin[rows] - s_lo) / max(s_hi - s_lo, 1e-12)
        lo, hi = res.band_of(f * (1 - 3 * p["zeta"])), res.band_of(f * (1 + 3 * p["zeta"]))
    else:
        lo = np.full(rows.size, int(res.band_of(u.f_Hz[0])))
        hi = np.full(rows.size, int(res.band_of(u.f_Hz[1])))
    out = {}
    for c in u.channels:
        if c in res.e:
            m = res.mask(c)
            for r, a, z in zip(rows, lo, hi):
                m[r, a:z + 1] = True
            out[c] = m
    return out


def _drift_cells(u, res: Residual) -> dict:
    """The cells of a ``ratio_drift`` record: in each run of its speed range, the bands from the model's line
    (h·Ω/2π) to the data's (its ratio read there, interpolated between the readings) and one either side, in its
    channels.  The model's fixed ratio misses the drifting line by a few bands at the top speed: an effect whose gain
    lies there (trial 30b wheel A, the cage slipping 5 %: a test stand of peak gain 0.27, a notch under the model's
    ball-pass lines where the data's had moved away) was fitted to the drift."""
    ctx = res.ctx
    p = u.parameters
    if not p.get("readings_rpm"):
        return {}
    rpm = np.abs(ctx.omega[ctx.runs]) * 60.0 / (2 * np.pi)
    rows = np.flatnonzero((rpm >= u.speed_rpm[0] - 1e-6) & (rpm <= u.speed_rpm[1] + 1e-6))
    spin = rpm[rows] / 60.0
    h_run = np.interp(rpm[rows], np.asarray(p["readings_rpm"], float), np.asarray(p["readings_h"], float))
    # from the model's line (the lowest and highest of those one drifting line was read from) to the data's
    model_h = [float(x) for x in p.get("model_h") or [p["h"]]]
    f_lo, f_hi, f_data = min(model_h) * spin, max(model_h) * spin, h_run * spin
    lo = np.maximum(res.band_of(np.minimum(f_lo, f_data)) - 1, 0)
    hi = np.minimum(res.band_of(np.maximum(f_hi, f_data)) + 1, ctx.n_bands - 1)
    out = {}
    for c in u.channels:
        if c in res.e:
            m = res.mask(c)
            for r, a, z in zip(rows, lo, hi):
                m[r, a:z + 1] = True
            out[c] = m
    return out


def _trend_cells(u, res: Residual) -> dict:
    """The cells of a ``gain_trend`` record: the band of each line it read (``read_h``: those that hold the trend and
    those that do not, an amplitude law fitted to one line having taken its share) in each run of its speed range, in
    its channels."""
    ctx = res.ctx
    rpm = np.abs(ctx.omega[ctx.runs]) * 60.0 / (2 * np.pi)
    rows = np.flatnonzero((rpm >= u.speed_rpm[0] - 1e-6) & (rpm <= u.speed_rpm[1] + 1e-6))
    hs = np.asarray(u.parameters.get("read_h", u.parameters.get("lines_h", ())), float)
    out = {}
    for c in u.channels:
        if c in res.e and hs.size:
            m = res.mask(c)
            for r in rows:
                m[r, res.band_of(hs * rpm[r] / 60.0)] = True
            out[c] = m
    return out


def holds_content(u, res: Residual) -> bool:
    """Whether the cells of record ``u`` (:func:`cells_of`) hold at least their own fraction of the waterfall's cells'
    share of the misplaced power left: no less than an average patch of the residual.  A record whose cells hold less
    describes nothing the residual holds: the lines a moving track lifts must be misplaced in the bands the metric
    reads (family wheel 7's speed sidebands read against their carrier: lifted 4-6 dB as lines, their bands matched
    by the model, a track through them held 3e-7 of what was left)."""
    cells = cells_of(u, res)
    n = sum(int(np.sum(m)) for m in cells.values())
    total = sum(int(np.size(x)) for x in res.e.values())
    if n == 0 or total == 0:
        return False
    share = res.measure(cells)[0]
    if share >= n / total:
        return True
    return u.signature == "moving_resonance" and share >= TRACK_SHARE_FLOOR * n / total and lifted_hold(u, res, total)


#: An effect the search added is taken back when at least this share of what it gains (misplaced power, on the data
#: as given) lies in the cells of what the residual holds that no class explains: it was fitted to that content.
FORCED_SHARE = 0.5


def forced_effects(diag, opened: Opened, search_before: State, search_after: State, found, res: Residual) -> list:
    """[(effect, signature)] of the effects the search added after its base (not the wheel's ``suspension_modes``,
    not the lines completed into the base) whose gain lies for :data:`FORCED_SHARE` or more in the cells of a record
    of ``found`` (:func:`cells_of`): each effect's gain is the drop of misplaced power from the final state with it
    taken out (the other effects applied again to the starting state, in their order) to the final state, cell by
    cell, on the data as given."""
    base = {id(h.effect) for h in diag.hypotheses if h.passed and (h.base_line or h.effect.kind == "suspension_modes")}
    cells = [(u, cells_of(u, res)) for u in found]
    out = []
    for e in search_after.effects:
        if id(e) in base:
            continue
        on_track = on_a_moving_track(e, found) or on_a_moving_skirt(e, found)
        if on_track:
            out.append((e, on_track))
            continue
        without = take_back.without(search_before, search_after.effects, e)
        if without is None:
            continue
        res0 = Residual.of(opened.raw, without.copy())
        gain = {c: res0.e[c] - res.e[c] for c in res.e}
        total = float(sum(np.nansum(g) for g in gain.values()))
        if total <= 0:
            continue
        for u, m in cells:
            inside = float(sum(np.nansum(gain[c][mask]) for c, mask in m.items()))
            if inside >= FORCED_SHARE * total:
                out.append((e, u.signature))
                break
    return out


def finish(diag, opened: Opened, bearings=(), rebuild=None):
    """``diag`` (a :class:`~rwadist.diagnose.search.Diagnosis` of the search on ``opened.ctx``) measured on the data
    as given and described: its context, states and errors those of the data as given (where the fixed lines and
    copies taken out before the search stay unexplained); its ``unexplained`` records (fixed lines and copies first,
    then what the final model's residual on the data the search read holds, :func:`describe_residual`); the effects
    the search fitted to that content taken back (:func:`forced_effects`: their hypotheses marked ``forced_by``, the
    model made again by ``rebuild(state, hypotheses)``, the content described on the state without them; an effect
    taken back for a ``moving_resonance`` that is not described without it is kept); the
    narrow-line metric and the lines' candidate causes."""
    bearings = tuple(bearings or ())
    search_before, search_after = diag.state_before, diag.state_after
    if opened.ctx is not opened.raw:
        s0 = search_before.copy()
        diag.state_before = s0
        diag.error_before, diag.rms_error_before = opened.raw.error(s0), opened.raw.rms_error(s0)
    diag.contrast_error_before = opened.raw.contrast_error(diag.state_before)
    found, res = _described(diag, opened, search_after, bearings)
    forced = forced_effects(diag, opened, search_before, search_after, found, res) if found and rebuild else []
    while forced:
        gone, state = without_taken_back(search_before, search_after.effects,
                                         with_groups(diag.hypotheses, {id(e): sig for e, sig in forced}))
        found_without, res_without = _described(diag, opened, state, bearings)
        # a moving resonance read on the lines of the effect it takes back is gone with them: the take-back stands
        # only where one is still described without the effect (else the effect's own lines were the track's
        # evidence: the E-like wheel's speed sidebands, read against their carrier, were taken back as fitted to a
        # moving resonance that was not described once they were out)
        lost = [x for x in forced if x[1] == "moving_resonance"
                and not any(u.signature == "moving_resonance" for u in found_without)]
        # nor does a take-back stand that leaves the model worse than the one the search started from: the effects
        # after it were fitted beside it (ROSS family wheel 5 on a stand at half its axial mode: the wheel's modes
        # refitted beside a test stand the moving resonance's take-back removed, the error 0.53 -> 0.70)
        if diag.error_after > diag.error_before:
            found, res = _described(diag, opened, search_after, bearings)
            break
        if not lost:
            for h in diag.hypotheses:
                if id(h.effect) in gone:
                    h.passed, h.forced_by = False, gone[id(h.effect)]
            diag.model = rebuild(state, diag.hypotheses)
            found, res = found_without, res_without
            break
        forced = [x for x in forced if all(x[0] is not y[0] for y in lost)]
        if not forced:
            found, res = _described(diag, opened, search_after, bearings)
    diag.unexplained = tuple(found)
    # (a line of a source outside the wheel, :mod:`.one_channel_lines`, :mod:`.range_lines`, is no relation of the
    # wheel's lines: both say the translation mode they are not lifted by)
    diag.line_causes = line_causes(diag, bearings, [u.h for u in found if u.h is not None
                                                    and "translation_Hz" not in u.parameters])
    diag.bearings = bearings
    # the lines the search added to an empirical base carry the sense their x/y phase reads, as the base's do
    from .start_model import sensed_lines

    if getattr(diag, "ctx", None) is not None:
        diag.model = sensed_lines(diag)
    return diag
