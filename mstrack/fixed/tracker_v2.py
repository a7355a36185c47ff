"""Fixed-point tracker v2: the executable specification of core v2 (float: mstrack/track/float_v2.py).

Per frame (all integer; blocks in :mod:`mstrack.fixed.blocks_v2` and :mod:`mstrack.fixed.blocks`):

1. D = ms_decimation(w8, h8) (x2 while lost); the tracker works on the
   decimated image ``frame[::D, ::D]`` and its colour bins.
2. Window diameters wd, hd = round((1 + pad) (w, h) / D); flat kernel tables
   (:class:`ms_kernel`); the model at this window, Qw = ms_model_scale(Qn, K).
3. Region = window box + MARGIN decimated px per side (+ the search offset
   while lost), captured; mean shift (:func:`ms_meanshift`, the paper's
   loop) from the last centre; while lost also from 8 start points at
   +-search_step window diameters (search_iter iterations each).
4. rho = ms_rho_out(S, K); share and spread from :func:`ms_target_stats` at
   the final centre; confidence; the best start point wins while lost; the
   search state from the confidence; the reported status from the loss flag
   (ms_ring_share, ms_loss_flag against rho0 = rho at init).
5. References (rho_ref, share_ref) follow confident frames by a shift;
   the size changes by ms_scale every frame.

Raw integers of each frame are in ``TrackResult.extra`` (:data:`RESULT_FIELDS_V2`).
"""
from __future__ import annotations

import numpy as np

from ..track.frames import check_frame
from ..track.params import TrackerParams
from ..track.types import Box, Status, TrackResult
from .blocks import (STOP_CODES, Region, clamp_centre, ms_bin_pass, ms_box_clip, ms_colour_bin, ms_grey, ms_histogram,
                     ms_kernel, ms_meanshift, ms_region, ms_rho_out, ms_round_centre, round_box)
from .blocks_v2 import (ONE, SIZE_FRAC, ModelV2, ms_bg_model, ms_confidence, ms_decimation, ms_loss_filter,
                        ms_loss_flag, ms_loss_jump, ms_loss_latch, ms_lost_decimation, ms_model_scale, ms_ref_update, ms_region_v2, ms_resize, ms_ring_share, ms_scale, ms_share, ms_spread,
                        ms_target_stats,
                        ms_window_size, ms_box_size, q16, rate_shift, sixteenths, ms_joint_bin, ms_orient_bin,
                        ORIENT_FLAT,
                        ms_scale_gate, ms_scale_test, ms_scale_test_size, ms_model_update, ms_no_shrink,
                        ms_ring_guard, ms_chroma_bin)
from .formats import FixedParams, widths

# Integer fields of one v2 result (what result word v2 will carry).
RESULT_FIELDS_V2 = ("cx", "cy", "w8", "h8", "rho", "confidence", "status", "iter", "decimation")
STATUS_CODES_V2 = {Status.OK: 0, Status.UNCERTAIN: 1, Status.LOST: 2, Status.REACQUIRED: 3,
                   Status.INIT: 4, Status.CLIPPED: 5, Status.ERROR: 6}


def joint_bins_region(frame: np.ndarray, d: int, bits: int, T: int, reg: Region, chroma: int = 0) -> np.ndarray:
    """``ms_joint_bin(ms_colour_bin(img), ms_orient_bin(ms_grey(frame), T)[::d, ::d])`` of the
    decimated image ``img = frame[::d, ::d]`` over region ``reg`` only (the region capture): the
    grey of the frame pixels under the region and its 1-px ring, Gx, Gy as ms_orient_bin forms
    them at the region's pixels (integers: the same values), 8 on the frame's 1-px border."""
    fh, fw = frame.shape[:2]
    img = frame[::d, ::d][reg.y: reg.y + reg.h, reg.x: reg.x + reg.w]
    c = ms_chroma_bin(img, bits, chroma) if chroma else ms_colour_bin(img, bits)
    n, m = c.shape
    if n == 0 or m == 0:
        return c
    y0, y1 = d * reg.y, d * (reg.y + n - 1)  # frame rows / columns of the region's first and last pixel
    x0, x1 = d * reg.x, d * (reg.x + m - 1)
    a0, a1, b0, b1 = max(y0 - 1, 0), min(y1 + 2, fh), max(x0 - 1, 0), min(x1 + 2, fw)
    g = ms_grey(frame[a0:a1, b0:b1])
    # the ring beyond the frame: any value (those pixels are on the frame border: bin 8)
    g = np.pad(g, ((a0 - (y0 - 1), y1 + 2 - a1), (b0 - (x0 - 1), x1 + 2 - b1)), mode="edge")

    def rows(dy: int) -> np.ndarray:  # grey rows Y + dy of the region's pixels (Y, X), every column
        return g[1 + dy: 1 + dy + d * (n - 1) + 1: d]

    def cols(a: np.ndarray, dx: int) -> np.ndarray:  # columns X + dx
        return a[:, 1 + dx: 1 + dx + d * (m - 1) + 1: d]

    # ms_orient_bin's sums regrouped (integers: the same values): Gx = V[x+1] - V[x-1] with the
    # vertical 1 2 1 sum V; Gy = D[x-1] + 2 D[x] + D[x+1] with the vertical difference D
    v = rows(-1) + 2 * rows(0) + rows(1)
    dd = rows(1) - rows(-1)
    gx = cols(v, 1) - cols(v, -1)
    gy = cols(dd, -1) + 2 * cols(dd, 0) + cols(dd, 1)
    ax, ay = np.abs(gx), np.abs(gy)
    o = np.where(ax + ay >= T, 4 * (gx < 0) + 2 * (gy < 0) + (ay > ax), ORIENT_FLAT)
    ys, xs = d * np.arange(reg.y, reg.y + n), d * np.arange(reg.x, reg.x + m)
    o[(ys == 0) | (ys == fh - 1), :] = ORIENT_FLAT
    o[:, (xs == 0) | (xs == fw - 1)] = ORIENT_FLAT
    return ms_joint_bin(c, o)


class FixedTrackerV2:
    """Bit-accurate model of tracker v2.  Use through :class:`mstrack.Tracker` (model="fixed", preset="v2")."""

    def __init__(self, params: TrackerParams | None = None, fixed: FixedParams | None = None) -> None:
        self.params = params or TrackerParams(preset="v2")
        if self.params.preset != "v2":
            raise ValueError("FixedTrackerV2 needs preset='v2'")
        self.fixed = fixed or FixedParams()
        p = self.params
        self.pad16 = sixteenths(p.pad, "pad")
        self.ring16 = sixteenths(p.bg_ring, "bg_ring")
        self.step16 = sixteenths(p.search_step, "search_step")
        self.ref_k = rate_shift(p.ref_rate)
        self.loss_rho16, self.loss_contrast16 = q16(p.loss_rho), q16(p.loss_contrast)
        self.loss_k = rate_shift(p.loss_smooth)
        self.loss_jump16 = sixteenths(p.loss_jump, "loss_jump")  # the motion latch (0: off, the default)
        self.loss_stay16 = q16(p.loss_stay)
        self.guard16 = q16(p.scale_ring_guard)  # the shrink guard (0: off, the default)
        self.model_k = rate_shift(p.model_rate, "model_rate") if p.model_rate > 0 else -1  # guarded model update (-1: off)
        self.model_con16 = q16(p.model_contrast)  # the update's contrast guard (Q.16 signed; -2**16: none)
        self.mix_k = rate_shift(p.model_mix, "model_mix")  # its running model's share 2**-mix_k (0: all)
        if p.kernel != "flat":
            raise ValueError("the fixed-point v2 model has the flat kernel only")
        if p.motion_gain > 0 or (p.scale_test > 0 and not p.scale_test_gate):
            raise ValueError("the fixed-point v2 model has the gated scale test only (scale_test needs "
                             "scale_test_gate) and no motion_gain (the float model's experimental option)")
        if p.max_window > 2 * self.fixed.max_half + 1:
            raise ValueError(f"max_window {p.max_window} > 2 max_half + 1 = {2 * self.fixed.max_half + 1}")
        self.widths = widths(p, self.fixed)
        self._shape: tuple[int, int] | None = None
        self._kernels: dict[tuple[int, int], ms_kernel] = {}

    # ------------------------------------------------------------------ helpers
    def _bins(self, frame: np.ndarray, d: int) -> np.ndarray:
        c = self._colour(frame[::d, ::d])
        if self.params.orient_T <= 0:
            return c
        # joint bins (the default, orient_T 64; 0 = colour bins): Sobel on the full-resolution grey frame
        return ms_joint_bin(c, ms_orient_bin(ms_grey(frame), self.params.orient_T)[::d, ::d])

    def _kernel(self, wd: int, hd: int) -> ms_kernel:
        """The flat ms_kernel of a wd x hd window (its tables depend on wd, hd only: kept, not rebuilt
        every frame; they are never modified)."""
        key = (wd, hd)
        ker = self._kernels.get(key)
        if ker is None:
            if len(self._kernels) > 64:
                self._kernels.clear()
            ker = self._kernels[key] = ms_kernel(wd, hd, "flat", self.fixed.kernel_bits)
        return ker

    def _geometry(self, d: int, dims: tuple[int, int]) -> tuple[int, int]:
        """Window diameters (decimated px), limited to the decimated frame's interior."""
        p = self.params
        hd_, wd_ = dims
        wd = ms_window_size(self.w8, self.pad16, d, min(p.max_window, wd_ - 2))
        hd = ms_window_size(self.h8, self.pad16, d, min(p.max_window, hd_ - 2))
        return wd, hd

    def _run(self, img: np.ndarray, Qw: np.ndarray, ker: ms_kernel, start8: tuple[int, int],
             reg: Region, max_iter: int, sub: np.ndarray | None = None):
        """Mean shift from ``start8`` (Q.CF, decimated px) in region ``reg`` of the decimated image
        ``img``; (c8, S, iters, stop, stats).  ``sub``: the region's colour bins if already captured."""
        fx, p = self.fixed, self.params
        cf = fx.centre_frac
        if sub is None:
            sub = self._capture(img, reg)
        tp = p.with_(max_iter=max_iter)
        r = ms_meanshift(sub, Qw, start8, reg, ker, tp, fx, p.n_bins_v2, self.widths.shift_q, q_frac=fx.model_frac)
        win = (ms_round_centre(r.c8[0], cf) - reg.x, ms_round_centre(r.c8[1], cf) - reg.y)
        st = ms_target_stats(sub, self.model.T, win, ker, fx.kernel_bits, self.pad16)
        return r.c8, r.S, r.iterations, r.stop, st

    def _capture(self, img: np.ndarray, reg: Region, frame: np.ndarray | None = None, d: int = 1) -> np.ndarray:
        """ms_region_capture for v2: the colour bins of the region's pixels of the decimated image
        ``img`` = frame[::d, ::d].  Joint bins (orient_T > 0): from ``frame``, the orientation of the
        region's pixels only (:func:`joint_bins_region`, the whole frame's bit for bit), or without
        ``frame`` (init) the region of the init frame's joint bin image ``self._joint``."""
        p = self.params
        if p.orient_T > 0:
            if frame is not None:
                return joint_bins_region(frame, d, p.colour_bits, p.orient_T, reg, p.chroma_bins)
            return self._joint[reg.y: reg.y + reg.h, reg.x: reg.x + reg.w]
        return self._colour(img[reg.y: reg.y + reg.h, reg.x: reg.x + reg.w])

    def _colour(self, img: np.ndarray) -> np.ndarray:
        """The colour bins of ``img``: ms_colour_bin, or ms_chroma_bin with chroma_bins (off by default)."""
        p = self.params
        return ms_chroma_bin(img, p.colour_bits, p.chroma_bins) if p.chroma_bins else ms_colour_bin(img, p.colour_bits)

    def _scale_verdict(self, sub: np.ndarray, reg: Region, c8d: tuple[int, int], d: int,
                       rho: int, dims: tuple[int, int]) -> int:
        """The gated scale test (the default, scale_test 0.05): rho of the windows of sizes x(1 -+ scale_test) at the
        final centre (ms_scale_test_size, ms_window_size, kernel tables, model at that window, one
        pixel pass and one bin pass each); a window outside the captured region does not count."""
        p, fx = self.params, self.fixed
        cf = fx.centre_frac
        d256 = round(p.scale_test * 256)
        win = (ms_round_centre(c8d[0], cf), ms_round_centre(c8d[1], cf))
        rhos: list[int | None] = []
        for up in (False, True):
            w8 = ms_scale_test_size(self.w8, d256, up)
            h8 = ms_scale_test_size(self.h8, d256, up)
            wd = ms_window_size(w8, self.pad16, d, min(p.max_window, dims[1] - 2))
            hd = ms_window_size(h8, self.pad16, d, min(p.max_window, dims[0] - 2))
            ker = self._kernel(wd, hd)
            if (win[0] - ker.ex < reg.x or win[1] - ker.ey < reg.y or win[0] + ker.ex >= reg.x + reg.w
                    or win[1] + ker.ey >= reg.y + reg.h):
                rhos.append(None)
                continue
            hist = ms_histogram(sub, reg, win, ker, p.n_bins_v2)
            S = ms_bin_pass(ms_model_scale(self.model.Qn, ker.K, fx.model_frac), hist, fx, fx.model_frac).S
            rhos.append(ms_rho_out(S, ker.K, fx))
        return ms_scale_test(rho, rhos[0], rhos[1], q16(p.scale_test_margin))

    def _box(self) -> Box:
        s = float(1 << self.fixed.centre_frac)
        cx, cy = self.c8[0] / s, self.c8[1] / s
        w, h = self.w8 / 256.0, self.h8 / 256.0
        return Box(cx + 0.5 - w / 2.0, cy + 0.5 - h / 2.0, w, h)

    # ------------------------------------------------------------------ API
    def init(self, frame: np.ndarray, box: Box | tuple[float, float, float, float]) -> TrackResult:
        """Round the float box to integers (edges half up) and initialise as the hardware does."""
        b = Box.of(box)
        if b.w <= 0 or b.h <= 0:
            raise ValueError(f"box must have positive width and height, got {b}")
        frame = check_frame(frame)
        fh, fw = frame.shape[:2]
        if fw >= (1 << self.fixed.coord_bits) or fh >= (1 << self.fixed.coord_bits):
            raise ValueError(f"frame {fw}x{fh} larger than coord_bits={self.fixed.coord_bits} allows")
        x, y, w, h = round_box(*b.as_tuple())
        ib, clipped = ms_box_clip(x, y, w, h, fw, fh, 4095)  # no shrink: large targets are decimated
        if ib is None:
            raise ValueError(f"box ({x}, {y}, {w}, {h}) leaves less than 3x3 px inside the "
                             f"interior of the {fw}x{fh} frame")
        p, fx = self.params, self.fixed
        cf = fx.centre_frac
        self._shape = (fh, fw)
        self.w8, self.h8 = ib.w << SIZE_FRAC, ib.h << SIZE_FRAC
        self.w0_8 = self.w8
        self.c8 = ((2 * ib.x + ib.w - 1) << (cf - 1), (2 * ib.y + ib.h - 1) << (cf - 1))
        d = ms_decimation(self.w8, self.h8, self.pad16, p.max_window)
        bins = self._bins(frame, d)
        hd_, wd_ = bins.shape
        sh = d.bit_length() - 1
        cd = (ms_round_centre(self.c8[0] >> sh, cf), ms_round_centre(self.c8[1] >> sh, cf))
        wb = ms_box_size(self.w8, d, min(p.max_window, wd_ - 2))
        hb = ms_box_size(self.h8, d, min(p.max_window, hd_ - 2))
        # keep the box inside the decimated interior
        cd = (min(max(cd[0], (wb - 1) // 2 + 1), wd_ - 2 - (wb - 1) // 2),
              min(max(cd[1], (hb - 1) // 2 + 1), hd_ - 2 - (hb - 1) // 2))
        self.model: ModelV2 = ms_bg_model(bins, cd[0], cd[1], wb, hb, self.ring16, p.n_bins_v2, fx.bg_frac)
        self.Qn0 = self.Qr = self.model.Qn  # the guarded model update's init and running models
        wd, hd = self._geometry(d, bins.shape)
        ker = self._kernel(wd, hd)
        Qw = ms_model_scale(self.model.Qn, ker.K, fx.model_frac)
        start8 = (self.c8[0] >> sh, self.c8[1] >> sh)
        # one pass at the init centre (no iteration) gives the references
        if p.orient_T > 0:
            self._joint = bins
        _, S, _, _, st = self._ref_pass(frame[::d, ::d], Qw, ker, start8)
        self.rho_ref = ms_rho_out(S, ker.K, fx)
        self.share_ref = ms_share(st)
        self.rho0 = self.rho_ref  # the loss flag's reference: rho at init
        self.rho_s = self.rho0    # the loss flag's filters start at the init values
        self.con_s = self.share_ref - ms_ring_share(st, ker.K)
        sp = ms_spread(st)
        self.spread_ref = sp if sp > 0 else ((128 << (fx.kernel_bits + 16)) // (16 + self.pad16) ** 2)
        self.lost = False
        self.lost_n = 0  # consecutive lost frames (the search's decimation)
        self.reported_lost = False
        self.loss_step = (0, 0)  # the motion latch: the last centre step (Q.cf frame px) and the latch bit
        self.loss_latch = False
        raw = {"cx": self.c8[0], "cy": self.c8[1], "w8": self.w8, "h8": self.h8, "rho": self.rho_ref,
               "confidence": ONE, "status": STATUS_CODES_V2[Status.CLIPPED if clipped else Status.INIT],
               "iter": 0, "decimation": d, "share": self.share_ref, "spread": self.spread_ref,
               "rho_s": self.rho_s, "contrast_s": self.con_s}
        return TrackResult(box=self._box(), centre=(self.c8[0] / (1 << cf), self.c8[1] / (1 << cf)),
                           rho_c=self.rho_ref / 65536.0, rho_e=0.0, alpha_c=1.0, alpha_e=0.0, iter_c=0,
                           iter_e=0, status=Status.CLIPPED if clipped else Status.INIT,
                           message="init box clipped" if clipped else "", confidence=1.0, extra=raw)

    def _ref_pass(self, img, Qw, ker, start8):
        """The pass at the (clamped) init centre without moving: S and the target statistics."""
        fx, p = self.fixed, self.params
        cf = fx.centre_frac
        reg = ms_region(start8, ker.ex, ker.ey, img.shape[1], img.shape[0], fx)
        c8 = clamp_centre(start8, reg, cf)
        win = (ms_round_centre(c8[0], cf), ms_round_centre(c8[1], cf))
        sub = self._capture(img, reg)
        hist = ms_histogram(sub, reg, win, ker, p.n_bins_v2)
        S = ms_bin_pass(Qw, hist, fx, fx.model_frac).S
        st = ms_target_stats(sub, self.model.T, (win[0] - reg.x, win[1] - reg.y), ker, fx.kernel_bits, self.pad16)
        return c8, S, 0, "shift", st

    def _model_update(self, frame: np.ndarray, d: int, c8d: tuple[int, int], w8: int, h8: int) -> None:
        """The guarded model update (model_rate > 0; off by default): ms_bg_model at the tracked
        box (centre c8d rounded, the size the frame tracked with, kept inside the decimated interior
        as at init) on the frame's bins, blended into the running model Qr by ms_model_update (shift
        model_k), and Qn = ms_model_update(Qn0, Qr, mix_k) (mix_k 0: Qn = Qr); T becomes the new model's."""
        p, fx = self.params, self.fixed
        cf = fx.centre_frac
        bins = self._bins(frame, d)
        hd_, wd_ = bins.shape
        wb = ms_box_size(w8, d, min(p.max_window, wd_ - 2))
        hb = ms_box_size(h8, d, min(p.max_window, hd_ - 2))
        cd = (ms_round_centre(c8d[0], cf), ms_round_centre(c8d[1], cf))
        cd = (min(max(cd[0], (wb - 1) // 2 + 1), wd_ - 2 - (wb - 1) // 2),
              min(max(cd[1], (hb - 1) // 2 + 1), hd_ - 2 - (hb - 1) // 2))
        new = ms_bg_model(bins, cd[0], cd[1], wb, hb, self.ring16, p.n_bins_v2, fx.bg_frac)
        m = self.model
        self.Qr = ms_model_update(self.Qr, new.Qn, self.model_k)
        self.model = ModelV2(Qn=ms_model_update(self.Qn0, self.Qr, self.mix_k), T=new.T, Q=m.Q, O=m.O)

    def update(self, frame: np.ndarray) -> TrackResult:
        """Track one frame.  Bad frames raise FrameError and leave the state unchanged."""
        if self._shape is None:
            raise RuntimeError("update() called before init()")
        frame = check_frame(frame, self._shape)
        p, fx = self.params, self.fixed
        cf = fx.centre_frac
        d0 = ms_decimation(self.w8, self.h8, self.pad16, p.max_window)
        d = ms_lost_decimation(d0, max(self.lost_n, int(self.lost)), p.search_widen)  # lost: at least one lost frame
        reach = d // (2 * d0) if self.lost else 1  # the widened search (search_widen; 1 without it)
        sh = d.bit_length() - 1
        img = frame[::d, ::d]
        wd, hd = self._geometry(d, img.shape[:2])
        ker = self._kernel(wd, hd)
        Qw = ms_model_scale(self.model.Qn, ker.K, fx.model_frac)
        start8 = (self.c8[0] >> sh, self.c8[1] >> sh)
        # one region per frame: the window box + MARGIN, + the search offsets while lost
        ox, oy = ((self.step16 * wd) >> 4) * reach, ((self.step16 * hd) >> 4) * reach
        reg, _ = ms_region_v2(start8, ker.ex, ker.ey, ox, oy, self.lost, img.shape[1], img.shape[0], fx)
        sub = self._capture(img, reg, frame, d)
        c8d, S, it, stop, st = self._run(img, Qw, ker, start8, reg, p.search_iter if self.lost else p.max_iter, sub)
        rho = ms_rho_out(S, ker.K, fx)
        share = ms_share(st)
        conf = ms_confidence(rho, share, self.rho_ref, self.share_ref)
        searched = 0
        if self.lost:
            for sy in (-1, 0, 1):
                for sx in (-1, 0, 1):
                    if sx == 0 and sy == 0:
                        continue
                    s8 = (max(start8[0] + (sx * ox << cf), 0), max(start8[1] + (sy * oy << cf), 0))
                    c2, S2, _, _, st2 = self._run(img, Qw, ker, s8, reg, p.search_iter, sub)
                    searched += 1
                    rho2, share2 = ms_rho_out(S2, ker.K, fx), ms_share(st2)
                    conf2 = ms_confidence(rho2, share2, self.rho_ref, self.share_ref)
                    if conf2 > conf:
                        c8d, S, st, rho, share, conf = c2, S2, st2, rho2, share2, conf2
        # search state (what the tracker does next) from the confidence
        if conf < q16(p.conf_reacquire if self.lost else p.conf_lost):
            state = Status.LOST
        elif self.lost:
            state = Status.REACQUIRED
        elif conf < q16(p.conf_uncertain):
            state = Status.UNCERTAIN
        else:
            state = Status.OK
        # reported status from the loss flag (float: report_status)
        ring = ms_ring_share(st, ker.K)
        self.rho_s = ms_loss_filter(self.rho_s, rho, self.loss_k)
        self.con_s = ms_loss_filter(self.con_s, share - ring, self.loss_k)
        ref = self.rho_ref if p.loss_ref_running else self.rho0  # (the running one: before this frame's update)
        flagged = ms_loss_flag(self.rho_s, ref, self.con_s, share, self.loss_rho16, self.loss_contrast16)
        c8 = (c8d[0] << sh, c8d[1] << sh)
        step = (c8[0] - self.c8[0], c8[1] - self.c8[1])
        motion: dict[str, int] = {}
        if self.loss_jump16 > 0:  # the motion latch (off by default)
            jump = ms_loss_jump(step, self.loss_step, self.w8, self.h8, self.loss_jump16, cf)
            self.loss_latch = ms_loss_latch(self.loss_latch, jump, self.rho_s, ref, self.loss_stay16)
            flagged = flagged or self.loss_latch
            motion = {"jump": abs(step[0] - self.loss_step[0]) + abs(step[1] - self.loss_step[1]),
                      "wh8": self.w8 + self.h8, "latch": int(self.loss_latch)}
        self.loss_step = step
        if flagged:
            status = Status.LOST if state == Status.LOST else Status.UNCERTAIN
        else:
            status = Status.REACQUIRED if self.reported_lost else Status.OK
        self.lost = state == Status.LOST
        self.lost_n = self.lost_n + 1 if self.lost else 0
        self.reported_lost = status == Status.LOST or (status == Status.UNCERTAIN and self.reported_lost)
        self.c8 = c8
        if state == Status.OK:
            self.rho_ref = ms_ref_update(self.rho_ref, rho, self.ref_k)
            self.share_ref = ms_ref_update(self.share_ref, share, self.ref_k)
        spread = ms_spread(st)
        if p.scale_gain > 0 and st.nt > 0:
            sp = spread
            if p.scale_test > 0 and p.scale_test_gate:  # the default (V2_COLOUR: off)
                sp = ms_scale_gate(spread, self.spread_ref,
                                   self._scale_verdict(sub, reg, c8d, d, rho, img.shape[:2]))
            s = ms_scale(sp, self.spread_ref, self.w8, self.w0_8, p)
            s = ms_no_shrink(s, ms_ring_guard(share, ring, self.guard16))
            fh, fw = self._shape
            w8_used, h8_used = self.w8, self.h8
            self.w8 = ms_resize(self.w8, s, fw)
            self.h8 = ms_resize(self.h8, s, fh)
        else:
            w8_used, h8_used = self.w8, self.h8
        if self.model_k >= 0 and state == Status.OK and not flagged and self.con_s >= self.model_con16:
            self._model_update(frame, d, c8d, w8_used, h8_used)
        raw = {"cx": self.c8[0], "cy": self.c8[1], "w8": self.w8, "h8": self.h8, "rho": rho,
               "confidence": conf, "status": STATUS_CODES_V2[status], "iter": it, "decimation": d,
               "share": share, "spread": spread, "stop": STOP_CODES[stop], "searched": searched,
               "nt": st.nt, "n_in": st.n_in, "nt_in": st.nt_in, "K": ker.K,
               "ring_share": ring, "state": STATUS_CODES_V2[state], "rho_s": self.rho_s,
               "contrast_s": self.con_s, **motion}
        return TrackResult(box=self._box(), centre=(self.c8[0] / (1 << cf), self.c8[1] / (1 << cf)),
                           rho_c=rho / 65536.0, rho_e=0.0, alpha_c=1.0, alpha_e=0.0, iter_c=it, iter_e=0,
                           status=status, confidence=conf / 65536.0, extra=raw)
