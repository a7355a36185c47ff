"""Per-frame latency of core v2 (ms_tracker_v2) on real sequences, Verilator fast path.

Usage: PYTHONPATH=. python studies/v2_latency.py Girl:40 MotorRolling:30 Couple:60 ...
(name:frames from the start of /work/shared/data/sequences/<name>, init box = ground truth of
frame 0, LANES = 4, default v2 generics, frames back to back).  Prints the init frame's latency
(last pixel -> result, clocks), the tracking frames' max / mean and the searched (lost-state)
frames' max; docs/blocks/ms_tracker_v2.md quotes it.
"""
import sys, json
from pathlib import Path
from mstrack.hw import fastsim
from mstrack.hw.cosim import expected_results_v2
from mstrack.fixed.blocks import round_box
from mstrack.io.data import load_sequence
from mstrack.fixed.tracker_v2 import FixedTrackerV2
SEQ_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "sequences"
if not SEQ_ROOT.is_dir():
    SEQ_ROOT = Path("/work/shared/data/sequences")
for arg in sys.argv[1:]:
    name, n = arg.split(":"); n = int(n)
    s = load_sequence(SEQ_ROOT / name)
    frames = [s.frame(i) for i in range(n)]
    box = round_box(*[float(v) for v in s.gt[0]])
    # lost state per frame (search): the frame is searched when the previous frame's state was lost
    t = FixedTrackerV2(); t.init(frames[0], box); searched = [0]
    for f in frames[1:]:
        searched.append(int(t.lost)); t.update(f)
    run = fastsim.simulate(frames, box, lanes=4, v2=True)
    lat = run.latencies
    tr = [l for l, sr in zip(lat[1:], searched[1:]) if not sr]
    lo = [l for l, sr in zip(lat[1:], searched[1:]) if sr]
    W, H = frames[0].shape[1], frames[0].shape[0]
    print(f"{name} {W}x{H} {n} frames: init {lat[0]}, tracking max {max(tr)} mean {sum(tr)/len(tr):.0f}, "
          f"searched (lost) frames {len(lo)} max {max(lo) if lo else '-'}; {run.cycles} clocks, {run.seconds:.1f} s")
