"""Per-frame latency of core v2 (ms_tracker_v2) with and without the gated scale test, Verilator fast path.

Usage: PYTHONPATH=. python studies/v2_scale_test_latency.py Girl:40 MotorRolling:40 Couple:40
(name:frames from the start of /work/shared/data/sequences/<name>, init box = ground truth of
frame 0, LANES = 4, MAX_FRAME_W 1024, top ms_tracker_v2; scale_test 0.05 + scale_test_gate, i.e.
generic SCALE_TEST_D256 13, against the default v2 parameters).  Both runs are checked bit-exact
against FixedTrackerV2.  Prints the init frame's latency, the first tracking frame's (the same state
in both runs: the difference is the scale test's cost) and the tracking frames' max / mean (last pixel
-> result, clocks); docs/blocks/ms_tracker_v2.md quotes it.
"""
import sys
from pathlib import Path

from mstrack.fixed import FixedParams
from mstrack.fixed.blocks import round_box
from mstrack.hw import fastsim
from mstrack.hw.cosim import COMPARED_FIELDS_V2, expected_results_v2
from mstrack.io.data import load_sequence
from mstrack.track.params import TrackerParams

SEQ_ROOT = Path(__file__).resolve().parents[2] / "shared" / "data" / "sequences"
if not SEQ_ROOT.is_dir():
    SEQ_ROOT = Path("/work/shared/data/sequences")
SCALE_TP = {"scale_test": 0.05, "scale_test_gate": True}
for arg in sys.argv[1:]:
    name, n = arg.split(":")
    s = load_sequence(SEQ_ROOT / name)
    frames = [s.frame(i) for i in range(int(n))]
    box = round_box(*[float(v) for v in s.gt[0]])
    for tag, kw in (("scale test", SCALE_TP), ("without", {})):
        tp = TrackerParams(preset="v2", **kw)
        run = fastsim.simulate(frames, box, tp, FixedParams(), lanes=4, v2=True, max_frame_w=1024,
                               top="ms_tracker_v2")
        diffs = fastsim.compare(run.results, expected_results_v2(frames, box, tp), COMPARED_FIELDS_V2)
        lat = [r["latency"] for r in run.results]
        print(f"{name} {tag}: mismatches {len(diffs)}, init {lat[0]}, first tracking frame {lat[1]}, "
              f"tracking max {max(lat[1:])} / mean {sum(lat[1:]) / len(lat[1:]):.0f}", flush=True)
