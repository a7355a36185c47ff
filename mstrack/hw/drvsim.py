"""The C driver against the RTL: ``sw/mstrack_drv.c`` driving ``ms_tracker_axi`` under Verilator.

The GHDL netlist of ``ms_tracker_axi`` (generics baked in) is verilated and linked with
``tools/hdl/drv_main.cpp`` and the driver compiled with ``-DMSTRACK_IO_EXTERN``: every register access
of the driver is one AXI4-Lite transaction on the simulated core, clocked with the video, which does
not wait for the CPU.  The harness calls ``mstrack_init`` and ``mstrack_start``, streams the frames,
runs ``mstrack_irq_handler`` whenever ``irq`` is high, records each result as the driver decoded it
and its raw word, and ends with ``mstrack_read_counters`` and ``mstrack_stop``
(docs/integration.md, "The driver against the RTL").

Usage::

    from mstrack.hw import drvsim
    from mstrack.hw.cosim import expected_results_v2

    run = drvsim.simulate_driver(frames, box)
    assert not drvsim.check_run(run, expected_results_v2(frames, box))
"""
from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Sequence, cast

import numpy as np

from . import fastsim, hdl
from .cosim import COMPARED_FIELDS, COMPARED_FIELDS_V2, CoreConfig, CoreConfigV2, diff_fields
from ..fixed import FixedParams
from ..fixed.multi_capacity import VideoTiming
from ..fixed.vhdl_pkg import RESULT_FLAGS, STATUS_V2, unpack_result, unpack_result_multi, unpack_result_v2
from ..track.params import TrackerParams

DRV_CPP = hdl.TOOLS_HDL_DIR / "drv_main.cpp"
SW_DIR = hdl.REPO_ROOT / "sw"
TOP = "ms_tracker_axi"

FLAG = {f: 1 << i for i, f in enumerate(RESULT_FLAGS)}
STATUS = {name: i for i, name in enumerate(STATUS_V2)}


def irq_bits() -> dict[str, int]:
    """The interrupt bits (INT_STATUS fields of regs/ms_tracker_regs.rdl: the driver's MSTRACK_IRQ_*)."""
    from .regs import register_map
    return {n: 1 << f.lsb for n, f in register_map()["INT_STATUS"].fields.items()}


class DriverSimError(RuntimeError):
    """The driver harness stopped early or could not run."""


@dataclass
class _HarnessRun:
    """What every driver harness run reports besides its results: ``calls`` (return codes of
    ``mstrack_init`` and ``mstrack_start`` / the enable), ``counters`` (``mstrack_read_counters`` at the
    end), ``other_irqs`` (interrupts without a result bit), SLVERR answers, clocks, wall time, the end
    status and the build time."""
    calls: dict[str, int] = field(default_factory=dict)
    counters: dict[str, int] = field(default_factory=dict)
    other_irqs: list[tuple[int, int]] = field(default_factory=list)
    bus_errors: int = 0
    cycles: int = 0
    seconds: float = 0.0
    status: str = "missing"
    detail: str = ""
    build_seconds: float = 0.0

    def _common(self, p: list[str]) -> bool:
        """Take one of the records every harness run writes (D, Q, C, B, E); False for another."""
        if p[0] == "D":
            self.calls[p[1]] = int(p[2])
        elif p[0] == "Q":
            self.other_irqs.append((int(p[1]), int(p[2])))
        elif p[0] == "C":
            self.counters = dict(zip(("results", "lost", "errors", "rejected", "dropped"), map(int, p[1:6])))
        elif p[0] == "B":
            self.bus_errors = int(p[1])
        elif p[0] == "E":
            self.status, self.cycles, self.seconds, self.detail = p[1], int(p[2]), float(p[3]), " ".join(p[4:])
        else:
            return False
        return True


@dataclass
class DriverRun(_HarnessRun):
    """Outcome of one driver co-simulation.

    ``results``: one dict per interrupt that carried a result, in order: ``word`` (the raw result
    word read from RES_RAW0..4), ``fields`` (``word`` decoded by Python), ``driver`` (the fields the
    driver read from the RES_* registers and decoded), ``irq`` (the INT_STATUS bits the handler saw and
    cleared), ``irq_cycle`` / ``handled_cycle`` (clock at which the handler was entered / returned).
    ``calls``: return codes of ``mstrack_init`` and ``mstrack_start``.  ``counters``: the driver's
    ``mstrack_read_counters`` at the end.  ``other_irqs``: interrupts without a result bit.
    """
    results: list[dict] = field(default_factory=list)

    def handler_clocks(self) -> list[int]:
        """Clocks from irq high to the handler's return, per result."""
        return [r["handled_cycle"] - r["irq_cycle"] for r in self.results]


def axi_generics(cfg: CoreConfig | CoreConfigV2, max_targets: int = 0, result_stream: bool = False,
                 shared: VideoTiming | None = None) -> dict[str, int]:
    """The generics of ms_tracker_axi for *cfg*: those of ms_tracker, results through the registers
    only (RESULT_STREAM false, as a CPU-only integration builds it; *result_stream*: true, the
    m_axis_result stream as well); *max_targets* >= 1: the multi-target core with that many slots
    (core v2), an engine per slot (ms_tracker_multi), or with *shared* (the capacity rule's video timing)
    one engine for every slot (ms_tracker_shared, ``SHARED_ENGINE``, its generics from
    :func:`mstrack.hw.multi_core.shared_core_generics`)."""
    g: dict[str, int] = dict(cfg.tracker_generics() if isinstance(cfg, CoreConfigV2) else cfg.generics())
    g["RESULT_STREAM"] = int(result_stream)
    if max_targets:
        if not isinstance(cfg, CoreConfigV2) or not 1 <= max_targets <= 16:
            raise ValueError("a multi-target core is core v2 with 1 .. 16 slots")
        g["MAX_TARGETS"] = max_targets
    if shared is not None:
        if not max_targets:
            raise ValueError("a shared engine needs max_targets >= 1")
        from .multi_core import pass_costs, shared_core_generics
        sg = shared_core_generics(cfg.tp, cfg.fp, max_targets, shared, cfg.max_frame_w,
                                  costs=pass_costs(cfg.lanes))
        g["SHARED_ENGINE"] = 1
        g.update({k: v for k, v in sg.items() if k not in g})
    return g


def build_driver(cfg: CoreConfig | CoreConfigV2, verbose: bool = False, max_targets: int = 0,
                 result_stream: bool = False, shared: VideoTiming | None = None) -> tuple[Path, float]:
    """Build (or find in the cache) the driver harness for *cfg* (*max_targets*, *result_stream*,
    *shared* as :func:`axi_generics`): (executable, seconds spent building)."""
    import time
    g = axi_generics(cfg, max_targets, result_stream, shared)
    vg = {k: (v != 0) if k in ("RESULT_STREAM", "SHARED_ENGINE") else v for k, v in g.items()}
    t0 = time.monotonic()
    net_dir = fastsim.FASTSIM_DIR / f"netlist_{fastsim._generics_hash(g)}_{TOP}"
    with fastsim._lock(net_dir.with_suffix(".lock")):
        vfile = hdl.ghdl_to_verilog(TOP, vg, out_path=net_dir / f"{TOP}.v")
    exe, built = fastsim.verilate(vfile.read_text(), g, TOP, [DRV_CPP, SW_DIR / "mstrack_drv.c"],
                                  include_dirs=[SW_DIR, hdl.TOOLS_HDL_DIR], defines=["MSTRACK_IO_EXTERN"],
                                  exe_name="Vdrv",
                                  verbose=verbose)
    return exe, (time.monotonic() - t0) if built else 0.0


def _run_harness(exe: Path, frames: Iterable[np.ndarray], max_frame_w: int, job: list[str],
                 workdir: Path | str | None, parse: Callable[[Path], _HarnessRun]) -> tuple[_HarnessRun, int]:
    """Write the pixels and the job (its ``width``, ``height``, ``frames``, ``pixels`` lines first, then
    *job*), run the harness *exe*, parse its out.txt with *parse*: (the run, the number of frames)."""
    import subprocess
    tmp = tempfile.TemporaryDirectory(prefix="drvsim_") if workdir is None else None
    wd = Path(tmp.name) if tmp is not None else Path(workdir)  # type: ignore[arg-type]
    wd.mkdir(parents=True, exist_ok=True)
    try:
        n, w, h = fastsim._write_pixels(frames, wd / "pixels.bin")
        if w > max_frame_w:
            raise ValueError(f"frame width {w} > max_frame_w {max_frame_w}")
        lines = [f"width {w}", f"height {h}", f"frames {n}", f"pixels {wd / 'pixels.bin'}", f"results {n}", *job]
        (wd / "job.txt").write_text("\n".join(lines) + "\n")
        r = subprocess.run([str(exe), str(wd / "job.txt"), str(wd / "out.txt")], capture_output=True, text=True)
        if r.returncode not in (0, 3) or not (wd / "out.txt").exists():
            raise DriverSimError(f"driver harness failed (exit {r.returncode}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
        return parse(wd / "out.txt"), n
    finally:
        if tmp is not None:
            tmp.cleanup()


def _finish(run: _HarnessRun, build_s: float, check: bool, progress: str) -> None:
    """Record the build time; with *check*, raise :class:`DriverSimError` unless the run ended done."""
    run.build_seconds = build_s
    if check and run.status != "done":
        raise DriverSimError(f"driver harness stopped: {run.status} {run.detail} (after {run.cycles} clocks, "
                             f"{progress})")


def _parse(out: Path, g: dict[str, int], v2: bool) -> DriverRun:
    run = DriverRun()
    unpack = unpack_result_v2 if v2 else unpack_result
    for line in out.read_text().splitlines():
        p = line.split()
        if not p or run._common(p):
            continue
        if p[0] == "R":
            word = int(p[2], 16)
            drv = {k: int(v) for k, v in (kv.split("=", 1) for kv in p[6:])}
            run.results.append({"word": word, "fields": unpack(word, g), "driver": drv, "irq": int(p[3]),
                                "irq_cycle": int(p[4]), "handled_cycle": int(p[5])})
    return run


def simulate_driver(frames: Iterable[np.ndarray], box: tuple[int, int, int, int], tp: TrackerParams | None = None,
                    fp: FixedParams | None = None, *, v2: bool = True, lanes: int | None = None,
                    max_frame_w: int = 2048, hblank: int = 0, vblank: int = 0, io_gap: int = 0,
                    irq_mask: int = 15, watchdog: int | None = None, tail: int = 200,
                    workdir: Path | str | None = None, check: bool = True) -> DriverRun:
    """Run the driver against ms_tracker_axi on *frames*, the init box *box* given by ``mstrack_start``.

    v2: core v2 (PRESET 1, tracker v2 parameters, default), else the paper core.  hblank, vblank: video
    blanking in clocks (:data:`mstrack.hw.fastsim.HD1080P60`); with none, the core back-pressures the
    video while it tracks.  io_gap: idle clocks before each register access (a slower CPU).
    irq_mask: the interrupts enabled (``MSTRACK_IRQ_*``, :func:`irq_bits`).  Raises :class:`DriverSimError` when the run
    does not end with every result read (unless ``check`` is false).
    """
    from ..fixed.vhdl_pkg import DEFAULT_LANES
    fp = fp or FixedParams()
    lanes = lanes or DEFAULT_LANES
    cfg: CoreConfig | CoreConfigV2
    if v2:
        cfg = CoreConfigV2(tp or TrackerParams(preset="v2"), fp, lanes=lanes, max_frame_w=max_frame_w)
    else:
        cfg = CoreConfig(tp or TrackerParams(), fp, lanes=lanes, max_frame_w=max_frame_w)
    g = cfg.generics()
    exe, build_s = build_driver(cfg)
    job = {"init_x": int(box[0]), "init_y": int(box[1]), "init_w": int(box[2]), "init_h": int(box[3]),
           "irq_mask": irq_mask, "hblank": hblank, "vblank": vblank, "io_gap": io_gap, "tail": tail,
           "watchdog": watchdog if watchdog is not None else fastsim.default_watchdog(g)}
    res, n = _run_harness(exe, frames, max_frame_w, [f"{k} {v}" for k, v in job.items()], workdir,
                          lambda out: _parse(out, g, v2))
    run = cast(DriverRun, res)
    _finish(run, build_s, check, f"{len(run.results)} results of {n}")
    return run


def check_run(run: DriverRun, expected: Sequence[dict[str, int]], v2: bool = True) -> list[str]:
    """Everything the driver run must show for the model's *expected* results, one string per
    difference (empty: the driver and the core agree with the model):

    * ``mstrack_init`` and ``mstrack_start`` returned MSTRACK_OK, no bus error;
    * one result interrupt per frame; the raw word's fields equal the model's, field by field;
    * the driver's decoded fields (read from the RES_* registers) equal the raw word's;
    * the interrupt bits: result always, lost / reacquired (v2) exactly on the model's lost /
      reacquired results, error exactly when the model's result carries the error flag;
    * the counters: results, lost, errors equal the model's counts, nothing rejected or dropped.
    """
    out = []
    if run.calls != {"init": 0, "start": 0}:
        out.append(f"driver calls returned {run.calls} (MSTRACK_OK = 0)")
    if run.bus_errors:
        out.append(f"{run.bus_errors} register accesses answered SLVERR")
    fields = COMPARED_FIELDS_V2 if v2 else COMPARED_FIELDS
    irq = irq_bits()
    for i in range(max(len(run.results), len(expected))):
        if i >= len(run.results):
            out.append(f"frame {i}: no result read by the driver")
            continue
        if i >= len(expected):
            out.append(f"frame {i}: extra result read by the driver")
            continue
        got, exp = run.results[i], expected[i]
        d = diff_fields(got["fields"], exp, fields)
        if d:
            out.append(f"frame {i}: raw word: " + "; ".join(d))
        drv = got["driver"]
        bad = [f"{k}: driver={v} word={got['fields'][k]}" for k, v in drv.items()
               if k != "valid" and got["fields"].get(k) != v]
        if drv.get("valid") != 1:
            bad.append(f"valid: driver={drv.get('valid')}")
        if bad:
            out.append(f"frame {i}: driver decode: " + "; ".join(bad))
        want = irq["result"] | (irq["error"] if exp["flags"] & FLAG["error"] else 0)
        if v2:
            want |= irq["lost"] if exp["status"] == STATUS["lost"] else 0
            want |= irq["reacquired"] if exp["status"] == STATUS["reacquired"] else 0
        else:
            want |= irq["lost"] if exp["flags"] & FLAG["lost"] else 0
        if got["irq"] != want:
            out.append(f"frame {i}: interrupt bits {got['irq']:#x}, expected {want:#x}")
    if run.other_irqs:
        out.append(f"interrupts without a result: {run.other_irqs[:5]}")
    lost = sum(1 for e in expected if (e["status"] == STATUS["lost"] if v2 else e["flags"] & FLAG["lost"]))
    errors = sum(1 for e in expected if e["flags"] & FLAG["error"])
    want_c = {"results": len(expected), "lost": lost, "errors": errors, "rejected": 0, "dropped": 0}
    if run.counters != want_c:
        out.append(f"counters {run.counters}, expected {want_c}")
    return out


# ----------------------------------------------------------------------------- multi-target cores
@dataclass
class DriverMultiRun(_HarnessRun):
    """Outcome of a driver co-simulation of a multi-target core (:func:`simulate_driver_multi`).

    ``frames``: one dict per result interrupt: ``mask`` (the driver's ``target_mask``), ``irq``,
    ``irq_cycle``, ``handled_cycle``, ``frame_count`` (RES_MASK's), ``box_rejected``, ``add_refused`` (the
    driver's ``dev.box_rejected``, ``dev.add_refused`` after the handler) and ``words``: ``{id: {"word", "fields",
    "driver"}}`` (the raw word read again, Python's decode of it, the driver's ``target[id]``).
    ``ops``: each ``mstrack_add`` / ``mstrack_remove`` the harness called: ``label``, ``op``, ``rc``, ``id``
    (add), ``before`` / ``after`` (frames whose first pixel had been taken before the call / at its
    return).  ``box_rejected``, ``live``, ``add_refused``, ``shared_engine``: the driver's ``dev.box_rejected``,
    ``mstrack_live``, ``dev.add_refused`` and ``dev.shared_engine`` at the end.
    ``stream``: with a result stream sink (:func:`simulate_driver_multi` *result_gap*), each beat it
    took: its fields (:func:`mstrack.fixed.vhdl_pkg.unpack_result_multi`) with ``word`` (the raw word, the
    target id at its top bits), ``last`` and ``cycle``; ``None`` without one.
    """
    frames: list[dict] = field(default_factory=list)
    ops: list[dict] = field(default_factory=list)
    box_rejected: int = 0
    live: int = 0
    add_refused: int = 0
    shared_engine: int = 0
    stream: list[dict] | None = None

    def handler_clocks(self) -> list[int]:
        """Clocks from irq high to the handler's return (every target's word read), per frame."""
        return [f["handled_cycle"] - f["irq_cycle"] for f in self.frames]

    def commands(self, max_targets: int) -> dict[int, list[tuple]]:
        """The commands the core was given, keyed by the frame they apply to (:func:`mstrack.hw.cosim_multi.expected_multi`):
        each op at the frame whose first pixel had not been taken when it was called (ValueError when a
        frame started during the call: the frame it applies to is then not known).  A remove of a label
        whose add failed was never given to the core (the driver refuses the id itself)."""
        ids: dict[str, int] = {}
        out: dict[int, list[tuple]] = {}
        for op in self.ops:
            if op["before"] != op["after"]:
                raise ValueError(f"{op['op']} {op['label']}: frame {op['before']} started during the call")
            if op["op"] == "add":
                out.setdefault(op["before"], []).append(("add", op["box"]))
                if op["rc"] == 0:
                    ids[op["label"]] = op["id"]
            elif op["label"] in ids and ids[op["label"]] < max_targets:
                out.setdefault(op["before"], []).append(("remove", ids[op["label"]]))
        return out


def _parse_multi(out: Path, ops: Sequence[tuple], g: dict[str, int]) -> DriverMultiRun:
    run = DriverMultiRun()
    boxes = {op[2]: tuple(op[3]) for op in ops if op[1] == "add"}
    for line in out.read_text().splitlines():
        p = line.split()
        if not p or run._common(p):
            continue
        if p[0] == "M":
            run.frames.append({"mask": int(p[2]), "irq": int(p[3]), "irq_cycle": int(p[4]),
                               "handled_cycle": int(p[5]), "frame_count": int(p[6]), "box_rejected": int(p[7]),
                               "add_refused": int(p[8]), "words": {}})
        elif p[0] == "W":
            word = int(p[3], 16)
            drv = {k: int(v) for k, v in (kv.split("=", 1) for kv in p[4:])}
            run.frames[int(p[1])]["words"][int(p[2])] = {"word": word, "fields": unpack_result_v2(word, g),
                                                         "driver": drv}
        elif p[0] == "A":
            run.ops.append({"op": "add", "label": p[1], "rc": int(p[2]), "id": int(p[3]), "before": int(p[4]),
                            "after": int(p[5]), "box": boxes[p[1]]})
        elif p[0] == "X":
            run.ops.append({"op": "remove", "label": p[1], "rc": int(p[2]), "before": int(p[3]), "after": int(p[4])})
        elif p[0] == "J":
            run.box_rejected, run.live, run.add_refused, run.shared_engine = map(int, p[1:5])
        elif p[0] == "T":
            if run.stream is None:
                run.stream = []
            word = int(p[2], 16)
            run.stream.append({**unpack_result_multi(word, g), "word": word, "last": int(p[1]), "cycle": int(p[3])})
    return run


def simulate_driver_multi(frames: Sequence[np.ndarray], ops: Sequence[tuple], tp: TrackerParams | None = None,
                          fp: FixedParams | None = None, *, max_targets: int = 2, lanes: int | None = None,
                          max_frame_w: int = 2048, hblank: int = 0, vblank: int = 0, io_gap: int = 0,
                          irq_mask: int | None = None, watchdog: int = 4_000_000, tail: int = 200,
                          result_gap: int | None = None, shared: VideoTiming | None = None,
                          workdir: Path | str | None = None, check: bool = True) -> DriverMultiRun:
    """Run the driver against ms_tracker_axi with ``MAX_TARGETS`` = *max_targets* (core v2 engines, the
    parameters *tp*, default tracker v2) on *frames*.  *ops*: ``(frame, "add", label, (x, y, w, h))`` or
    ``(frame, "remove", label)``, in order: the harness calls ``mstrack_add`` / ``mstrack_remove`` (the id
    its add of *label* returned) once the result of frame ``frame - 1`` has been read (frame 0: after
    ``mstrack_enable``, before the video).  Each result interrupt reads every target's word of the frame
    (``mstrack_read_frame`` in the handler).  Raises :class:`DriverSimError` when the run does not end
    with every frame's words read (unless ``check`` is false).  *result_gap*: None, results through the
    registers only (``RESULT_STREAM`` false); an int >= 0, the core built with its result stream too and
    a sink that takes a beat, then holds ``tready`` low *result_gap* clocks (``run.stream``): the words
    of a frame then come that far apart, as behind a slow DMA.  *shared*: the core with one engine for
    every slot (ms_tracker_shared, ``SHARED_ENGINE``) and this video timing in its capacity rule; None,
    an engine per slot (ms_tracker_multi)."""
    from ..fixed.vhdl_pkg import DEFAULT_LANES
    cfg = CoreConfigV2(tp or TrackerParams(preset="v2"), fp or FixedParams(), lanes=lanes or DEFAULT_LANES,
                       max_frame_w=max_frame_w)
    g = cfg.generics()
    lines = ["multi 1", f"hblank {hblank}", f"vblank {vblank}", f"io_gap {io_gap}", f"tail {tail}",
             f"watchdog {watchdog}"]
    if irq_mask is not None:
        lines.append(f"irq_mask {irq_mask}")
    if result_gap is not None:
        if result_gap < 0:
            raise ValueError(f"result_gap {result_gap}: >= 0 or None")
        lines.append(f"result_gap {result_gap}")
    labels: set[str] = set()
    for op in ops:
        fr, what, label = int(op[0]), op[1], str(op[2])
        if not label or any(c.isspace() for c in label):
            raise ValueError(f"op label {label!r}: one word")
        if what == "add":
            if label in labels:
                raise ValueError(f"label {label!r} added twice")
            labels.add(label)
            lines.append(f"op {fr} add {label} " + " ".join(str(int(v)) for v in op[3]))
        elif what == "remove":
            lines.append(f"op {fr} remove {label}")
        else:
            raise ValueError(f"op {what!r}: add or remove")
    exe, build_s = build_driver(cfg, max_targets=max_targets, result_stream=result_gap is not None, shared=shared)
    res, n = _run_harness(exe, frames, max_frame_w, lines, workdir, lambda out: _parse_multi(out, ops, g))
    run = cast(DriverMultiRun, res)
    _finish(run, build_s, check, f"{len(run.frames)} frames of {n}")
    return run


def mot_ops(seq, n_frames: int | None = None) -> list[tuple]:
    """The driver's ops for a MOT sequence (:class:`mstrack.io.mot.MotSequence`) as people appear and
    leave: each target added (its ground-truth box, rounded as the trackers round it) before its first
    frame, removed before the frame after its last; within a frame the removes come first, so a freed
    slot can take a new target.  *n_frames*: the frames streamed (default: all)."""
    from ..fixed.blocks import round_box
    n = len(seq) if n_frames is None else n_frames
    ops: list[tuple] = []
    for f in range(n):
        ops += [(f, "remove", f"id{t.id}") for t in seq.tracks.values() if t.last + 1 == f]
        ops += [(f, "add", f"id{t.id}", round_box(*seq.boxes_at(f)[t.id].as_tuple()))
                for t in seq.starting_at(f)]
    return ops


def check_run_multi(run: DriverMultiRun, model, max_targets: int) -> list[str]:
    """Everything a multi-target driver run must show for *model* (a
    :class:`mstrack.hw.cosim_multi.CoreModelMulti` fed ``run.commands(max_targets)``: :func:`expected_multi`),
    one string per difference:

    * ``mstrack_init`` and the enable returned MSTRACK_OK, no bus error;
    * each add / remove returned what the model's report says (the id of an add; MSTRACK_ERR_FULL for a
      refused add, MSTRACK_ERR_ARG for a remove of an id not live); the reports that come later (a box
      the engine rejects, an add the capacity rule refuses at its frame) are not the command's return;
    * one result interrupt per frame; its target mask is the ids of the model's words without
      ``no_target``; each target's raw word equals the model's word field by field (target id included),
      and the driver's fields (read from the RES_* registers) equal the raw word's;
    * the interrupt bits: result always; lost / reacquired / error exactly when a word of the frame has
      status lost / reacquired / flag error or rejected (the command bit is not compared: it follows the
      command reports, which the handler sees whenever they come);
    * the counters (frames, lost / error / rejected words) and, at the end, the live slots, the
      rejected boxes and the refused adds the handler saw (subsets of the model's: CMD_STATUS keeps the
      last report only);
    * with a result stream sink (``run.stream``): its beats are the model's words, frame by frame, field
      by field (target id included), ``tlast`` on each frame's last.
    """
    from .cosim_multi import CMD_BOX, CMD_CYCLES, CMD_OK, diff_words
    out = []
    if run.calls != {"init": 0, "start": 0}:
        out.append(f"driver calls returned {run.calls} (MSTRACK_OK = 0)")
    if run.bus_errors:
        out.append(f"{run.bus_errors} register accesses answered SLVERR")
    reports = [o for o in model.outcomes if o.code not in (CMD_BOX, CMD_CYCLES)]
    issued = []
    ids: dict[str, int] = {}
    for o in run.ops:                         # the commands the core was given (a remove of a failed add was not)
        if o["op"] == "add":
            issued.append(o)
            if o["rc"] == 0:
                ids[o["label"]] = o["id"]
        elif o["label"] in ids:
            issued.append(o)
    if len(issued) != len(reports):
        out.append(f"{len(issued)} commands given, the model reports {len(reports)}")
    for o, rep in zip(issued, reports):
        want = (0 if rep.code == CMD_OK else -5) if o["op"] == "add" else (0 if rep.code == CMD_OK else -3)
        if o["rc"] != want or (o["op"] == "add" and rep.code == CMD_OK and o["id"] != rep.target_id):
            out.append(f"{o['op']} {o['label']}: driver rc={o['rc']} id={o.get('id')}, model code={rep.code} "
                       f"id={rep.target_id}")
    irq = irq_bits()
    if len(run.frames) != len(model.frames):
        out.append(f"{len(run.frames)} result interrupts, the model has {len(model.frames)} frames")
    for i, (got, exp) in enumerate(zip(run.frames, model.frames)):
        live = {w["target_id"]: w for w in exp if not w["flags"] & FLAG["no_target"]}
        mask = sum(1 << k for k in live)
        if got["mask"] != mask or set(got["words"]) != set(live):
            out.append(f"frame {i}: targets {got['mask']:#x} ({sorted(got['words'])}), expected {mask:#x}")
        for k, w in sorted(got["words"].items()):
            if k not in live:
                continue
            d = diff_fields(w["fields"], live[k], COMPARED_FIELDS_V2)
            if d:
                out.append(f"frame {i} target {k}: raw word: " + "; ".join(d))
            drv = w["driver"]
            bad = [f"{f}: driver={v} word={w['fields'][f]}" for f, v in drv.items()
                   if f in w["fields"] and w["fields"][f] != v]
            if drv.get("valid") != 1 or drv.get("target_id") != k or drv.get("again_frame_count") != drv.get("frame_count"):
                bad.append(f"valid={drv.get('valid')} target_id={drv.get('target_id')} "
                           f"frame_count={drv.get('frame_count')} read again={drv.get('again_frame_count')}")
            if bad:
                out.append(f"frame {i} target {k}: driver decode: " + "; ".join(bad))
        want = irq["result"]
        for w in exp:
            want |= irq["lost"] if w["status"] == STATUS["lost"] else 0
            want |= irq["reacquired"] if w["status"] == STATUS["reacquired"] else 0
            want |= irq["error"] if w["flags"] & (FLAG["error"] | FLAG["rejected"]) else 0
        if got["irq"] & ~irq["command"] != want:
            out.append(f"frame {i}: interrupt bits {got['irq']:#x}, expected {want:#x} (command bit not compared)")
    other = [q for q in run.other_irqs if q[0] & ~irq["command"]]
    if other:
        out.append(f"interrupts without a result: {other[:5]}")
    words = model.results
    want_c = {"results": len(model.frames), "lost": sum(w["status"] == STATUS["lost"] for w in words),
              "errors": sum(bool(w["flags"] & FLAG["error"]) for w in words),
              "rejected": sum(bool(w["flags"] & FLAG["rejected"]) for w in words), "dropped": 0}
    if run.counters != want_c:
        out.append(f"counters {run.counters}, expected {want_c}")
    live_end = sum(1 << k for k in model.live)
    if run.live != live_end:
        out.append(f"live slots at the end {run.live:#x}, expected {live_end:#x}")
    boxed = sum(1 << o.target_id for o in model.outcomes if o.code == CMD_BOX)
    if run.box_rejected & ~boxed:
        out.append(f"rejected boxes {run.box_rejected:#x} not in the model's {boxed:#x}")
    refused = sum(1 << o.target_id for o in model.outcomes if o.code == CMD_CYCLES)
    if run.add_refused & ~refused:
        out.append(f"refused adds {run.add_refused:#x} not in the model's {refused:#x}")
    if run.stream is not None:
        out += [f"result stream: {d}" for d in diff_words(run.stream, model.frames)]
    return out


__all__ = ["DriverRun", "DriverSimError", "build_driver", "simulate_driver", "check_run", "axi_generics",
           "DriverMultiRun", "simulate_driver_multi", "check_run_multi", "mot_ops"]
