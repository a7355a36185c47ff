"""Diagnosis for docs/results_v2_mean.md: per sequence, the default float v2 AUC, the AUC with the
tracker's centres but the ground-truth size ("oracle size"), precision at 20 px, the median size
ratio box / truth and the truth's growth first -> last frame.

Usage: PYTHONPATH=. python studies/v2_oracle_size.py
"""
import numpy as np
from mstrack import Tracker
from mstrack.io.data import load_dataset
from mstrack.eval.metrics import IOU_THRESHOLDS, iou, valid_gt
from pathlib import Path
seqs = load_dataset(str(Path(__file__).resolve().parents[2] / "shared/data/sequences"))
def auc(io): return float(np.mean([(io > th).mean() for th in IOU_THRESHOLDS]))
for s in seqs:
    t = Tracker(model="float", preset="v2")
    bx=[]
    for i in range(len(s)):
        fr=s.frame(i)
        r = t.init(fr, s.init_box()) if i==0 else t.update(fr)
        bx.append(r.box.as_tuple())
    bx=np.array(bx); gt=s.gt[:len(bx)]; v=valid_gt(gt)
    io=iou(bx[v],gt[v])
    # oracle size: our centre, gt size
    c=bx[:,:2]+bx[:,2:]/2
    ob=np.c_[c-gt[:,2:]/2, gt[:,2:]]
    io2=iou(ob[v],gt[v])
    gc=gt[:,:2]+gt[:,2:]/2
    err=np.hypot(*(c-gc)[v].T)
    sz=np.sqrt(bx[:,2]*bx[:,3])/np.sqrt(gt[:,2]*gt[:,3])
    print(f"{s.name:12s} n={len(s):4d} size0={s.gt[0,2]:.0f}x{s.gt[0,3]:.0f} auc={auc(io):.3f} oracle_size={auc(io2):.3f} prec20={(err<20).mean():.2f} medsz={np.median(sz[v]):.2f} gtgrowth={np.sqrt(gt[-1,2]*gt[-1,3]/gt[0,2]/gt[0,3]):.2f}")
