"""Test vectors for the RTL: every intermediate of the fixed-point model on chosen frames.

:func:`dump_vectors` initialises :class:`~mstrack.fixed.FixedTracker` on frame 0
of a sequence (ground-truth box, rounded to integers as the hardware's init
port takes it), tracks every frame up to the last one asked for, and writes
``last_trace`` of the chosen frames:

* init frame: region (x, y, w, h), the colour and edge bins of the region
  (what the capture RAMs hold), the target histograms Q_c / Q_e and the result;
* update frames: region, region bins, and per feature and per iteration the
  centre (Q.CF), the integer window position, for the non-zero bins
  ``bins``/H/N/SX/SY and the weights w, then S, Sw, Swx, Swy; and the result
  (centre, rho out, alpha_c, iterations, stop codes, S_c, S_e, per-feature centres).

File format (version 1): gzip (mtime 0, no file name: byte-reproducible) of
JSON lines with sorted keys.  Line 1 is the header::

    {"format": "mstrack-vectors", "version": 1, "sequence": ..., "frames": [...],
     "frame_size": [W, H], "init_box": [x, y, w, h],
     "params": {"tracker": TrackerParams, "fixed": FixedParams},
     "generics": mstrack.fixed.vhdl_pkg.core_generics(tp, fp)}

then one line per chosen frame: ``{"frame": i, "kind": "init" | "update", "trace": ...}``.

Command line: ``python -m mstrack.hw.vectors SEQ_DIR --frames 0,1,5 --out FILE [--param NAME=VALUE]``,
or ``mstrack vectors ...`` once ``"mstrack.hw.vectors:register_cli"`` is in ``mstrack.cli.EXTENSIONS``.
"""
from __future__ import annotations

import argparse
import gzip
import json
import sys
from dataclasses import asdict
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..io.data import load_sequence
from ..fixed import FixedParams, FixedTracker
from ..fixed.blocks import round_box
from ..fixed.vhdl_pkg import DEFAULT_LANES, core_generics
from ..track.params import TrackerParams
from ..track.types import Box

FORMAT = "mstrack-vectors"
VERSION = 1


def _plain(o: Any) -> Any:
    """json default: numpy scalars/arrays and tuples to plain Python."""
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.floating):
        return float(o)
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def _line(obj: Any) -> bytes:
    return (json.dumps(obj, sort_keys=True, separators=(",", ":"), default=_plain) + "\n").encode()


def split_params(params: dict[str, Any]) -> tuple[TrackerParams, FixedParams]:
    """TrackerParams and FixedParams from one dict of fields; unknown names raise TypeError."""
    tp, rest = TrackerParams.split(params)
    fp, rest = FixedParams.split(rest)
    if rest:
        raise TypeError(f"unknown parameters: {sorted(rest)}")
    return tp, fp


def generate(seq_dir: str | Path, frames: list[int], lanes: int = DEFAULT_LANES,
             **params: Any) -> Iterator[dict[str, Any]]:
    """Yield the header, then one record per chosen frame (see the module docstring)."""
    frames = sorted(set(int(f) for f in frames))
    if not frames or frames[0] < 0:
        raise ValueError("frames must be non-negative frame indices")
    seq = load_sequence(seq_dir)
    if frames[-1] >= len(seq):
        raise ValueError(f"frame {frames[-1]} out of range: {seq.name} has {len(seq)} frames")
    tp, fp = split_params(params)
    trk = FixedTracker(tp, fp)
    f0 = seq.frame(0)
    ib = round_box(*Box.of(seq.gt[0]).as_tuple())
    yield {"format": FORMAT, "version": VERSION, "sequence": seq.name, "frames": frames,
           "frame_size": [int(f0.shape[1]), int(f0.shape[0])], "init_box": list(ib),
           "params": {"tracker": asdict(tp), "fixed": asdict(fp)},
           "generics": core_generics(tp, fp, lanes)}
    want = set(frames)
    trk.init_int(f0, *ib, trace=0 in want)
    if 0 in want:
        yield {"frame": 0, "kind": "init", "trace": trk.last_trace}
    for i in range(1, frames[-1] + 1):
        trk.update(seq.frame(i), trace=i in want)
        if i in want:
            yield {"frame": i, "kind": "update", "trace": trk.last_trace}


def dump_vectors(seq_dir: str | Path, frames: list[int], out: str | Path, lanes: int = DEFAULT_LANES,
                 **params: Any) -> Path:
    """Write the test vectors of ``frames`` of the sequence at ``seq_dir`` to ``out`` (.jsonl.gz).

    Parameters
    ----------
    seq_dir : path
        OTB/VOT sequence folder; the tracker is initialised on frame 0 with its ground truth.
    frames : list of int
        Frame indices to dump (0 = the init frame).
    out : path
        Output file; the same input always gives a byte-identical file.
    lanes : int
        LANES generic recorded in the header.
    **params
        TrackerParams and FixedParams fields.
    """
    out = Path(out)
    if not out.name.endswith(".gz"):
        raise ValueError(f"the vectors are gzip-compressed JSON lines: name the --out file *.jsonl.gz, "
                         f"not {out.name!r}")
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "wb") as raw, gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0) as gz:
        for rec in generate(seq_dir, frames, lanes, **params):
            gz.write(_line(rec))
    return out


def load_vectors(path: str | Path) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Read a vectors file: (header, records).  Raises ValueError on a wrong format or version."""
    with gzip.open(path, "rt") as f:
        lines = [json.loads(line) for line in f if line.strip()]
    if not lines or lines[0].get("format") != FORMAT:
        raise ValueError(f"{path}: not an {FORMAT} file")
    if lines[0].get("version") != VERSION:
        raise ValueError(f"{path}: version {lines[0].get('version')}, expected {VERSION}")
    return lines[0], lines[1:]


def _parse_frames(s: str) -> list[int]:
    return [int(v) for v in s.split(",") if v.strip()]


def add_arguments(ap: argparse.ArgumentParser) -> None:
    """Arguments of ``python -m mstrack.hw.vectors`` and ``mstrack vectors``."""
    ap.add_argument("seq_dir", help="sequence folder (or, with --format vhdl-files and --box, any video "
                                    "or image folder)")
    ap.add_argument("--frames", type=_parse_frames, default=[0, 1], help="comma separated, e.g. 0,1,5 "
                    "(vhdl-files: frames 0 .. the largest one are streamed)")
    ap.add_argument("--out", required=True, metavar="FILE.jsonl.gz|DIR",
                    help="output file, gzip-compressed JSON lines (jsonl: another extension is refused), "
                         "or folder (vhdl-files)")
    ap.add_argument("--lanes", type=int, default=DEFAULT_LANES)
    ap.add_argument("--format", choices=("jsonl", "vhdl-files"), default="jsonl",
                    help="jsonl: every fixed-point intermediate (default); vhdl-files: frames.txt, "
                         "expected.txt, generics.json for tb/vhdl/ms_tracker_file_tb.vhd (mstrack.hw.tb_files)")
    ap.add_argument("--box", help="vhdl-files: init box x,y,w,h (integers; default: the ground truth of frame 0)")
    ap.add_argument("--max-frame-width", type=int, default=2048, help="vhdl-files: MAX_FRAME_W (default 2048)")
    ap.add_argument("--rgb-packing", choices=("mstrack", "ug934"), default="mstrack",
                    help="vhdl-files: layout of the pixel words (the testbench's RGB_PACKING)")
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                    help="TrackerParams or FixedParams field (repeatable)")


def run(args: argparse.Namespace) -> int:
    """Handler of ``mstrack vectors`` / ``python -m mstrack.hw.vectors``."""
    params: dict[str, Any] = {}
    for it in args.param:
        k, sep, v = it.partition("=")
        if not sep:
            raise ValueError(f"--param expects NAME=VALUE, got {it!r}")
        try:
            params[k] = int(v)
        except ValueError:
            try:
                params[k] = float(v)
            except ValueError:
                params[k] = v
    if getattr(args, "format", "jsonl") == "vhdl-files":
        print(dump_vhdl_files(args.seq_dir, max(args.frames) + 1, args.out, args.lanes, box=args.box,
                              max_frame_w=args.max_frame_width, packing=args.rgb_packing, **params))
        return 0
    print(dump_vectors(args.seq_dir, args.frames, args.out, args.lanes, **params))
    return 0


def dump_vhdl_files(source: str | Path, n_frames: int, out: str | Path, lanes: int = DEFAULT_LANES,
                    box: str | None = None, max_frame_w: int = 2048, packing: str = "mstrack",
                    **params: Any) -> Path:
    """Files of the standalone VHDL testbench (:func:`mstrack.hw.tb_files.write_tb_files`) for the
    first ``n_frames`` frames of ``source`` (sequence folder, video or image folder); init box
    ``box`` ("x,y,w,h") or the sequence's ground truth on frame 0.  Returns the folder."""
    from .cosim import CoreConfig
    from ..io.data import VideoSource
    from .tb_files import write_tb_files

    src = VideoSource(source)
    if box:
        try:
            ib = tuple(int(v) for v in box.split(","))
        except ValueError:
            raise ValueError(f"--box wants integers x,y,w,h, got {box!r}") from None
        if len(ib) != 4:
            raise ValueError(f"--box wants x,y,w,h, got {box!r}")
    elif src.sequence is not None:
        ib = round_box(*Box.of(src.sequence.gt[0]).as_tuple())
    else:
        raise ValueError("--box x,y,w,h is required unless the source is a sequence folder with ground truth")
    frames: list[np.ndarray] = []
    for f in src.frames():  # on_bad="raise": never None
        assert f is not None
        frames.append(f)
        if len(frames) == n_frames:
            break
    tp, fp = split_params(params)
    cfg = CoreConfig(tp, fp, lanes=lanes, max_frame_w=max_frame_w)
    write_tb_files(out, frames, ib, cfg, packing={"mstrack": 0, "ug934": 1}[packing], source=str(source))
    return Path(out)


def register_cli(sub: argparse._SubParsersAction) -> None:
    """CLI extension (mstrack.cli.EXTENSIONS entry ``"mstrack.hw.vectors:register_cli"``): ``mstrack vectors``."""
    p = sub.add_parser("vectors", help="dump RTL test vectors (every fixed-point intermediate) of chosen frames",
                       description=__doc__.split("\n\n")[0])
    add_arguments(p)
    p.set_defaults(func=run)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m mstrack.hw.vectors", description=__doc__.split("\n\n")[0])
    add_arguments(ap)
    return run(ap.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
