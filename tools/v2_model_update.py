"""Issue 10 item 6: does a model update pay for tracker v2?  (It does not: docs/algorithm.md, "Tracker v2".)

Usage: python tools/v2_model_update.py BETA CONF_MIN [SEQ_ROOT]
Blends the background-weighted candidate histogram of the box into the model on frames with
status ok and confidence >= CONF_MIN: q' <- (1 - BETA) q' + BETA p'.  Prints the per-sequence and
overall AUC (float v2).  BETA = 0 is tracker v2 as it is.
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from mstrack.io.data import load_dataset
from mstrack.eval.metrics import iou, valid_gt, IOU_THRESHOLDS
from mstrack.track.float_v2 import FloatTrackerV2, window_pixels
from mstrack.track.params import TrackerParams
from mstrack.track.types import Status
beta=float(sys.argv[1]); cmin=float(sys.argv[2])
class Upd(FloatTrackerV2):
    def update(self, frame):
        r = super().update(frame)
        if beta>0 and r.status == Status.OK and r.confidence >= cmin:
            p = self.params; d = r.extra['decimation']
            bins = self._bins(frame, d)
            cx, cy = r.centre; w, h = self._size
            xs, ys, d2 = window_pixels(cx/d, cy/d, w/2/d, h/2/d, bins.shape[1], bins.shape[0])
            ph = np.bincount(bins[ys, xs], minlength=p.n_colour_bins).astype(float); ph /= max(ph.sum(),1)
            # background-weight the candidate like the model (same v factors implied by qb/q)
            v = np.where(self._q > 0, self._qb / np.where(self._q > 0, self._q, 1), 1.0)
            pb = ph * v; pb /= max(pb.sum(), 1e-12)
            self._qb = (1 - beta) * self._qb + beta * pb
        return r
ious=[]
for s in load_dataset(sys.argv[3] if len(sys.argv) > 3 else str(__import__('pathlib').Path(__file__).resolve().parents[2] / 'shared' / 'data' / 'sequences')):
    t=Upd(TrackerParams(preset='v2')); bx=[]
    for i,fr in enumerate(s.frames()):
        r=t.init(fr,s.init_box()) if i==0 else t.update(fr); bx.append(r.box.as_tuple())
    gt=s.gt[:len(bx)]; io=iou(np.array(bx),gt)[valid_gt(gt)]; ious.append(io)
    print(s.name[:6], '%.3f'%np.mean([(io>th).mean() for th in IOU_THRESHOLDS]), end='  ')
io=np.concatenate(ious); print('\nbeta',beta,'cmin',cmin,'AUC %.3f'%np.mean([(io>th).mean() for th in IOU_THRESHOLDS]))
