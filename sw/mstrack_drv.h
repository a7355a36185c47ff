/* mstrack_drv: bare-metal driver of the mstrack tracking core (rtl/ms_tracker_axi.vhd).
 *
 * Register offsets and fields come from the generated header ms_tracker_regs.h (PeakRDL, from
 * regs/ms_tracker_regs.rdl); the result word layout from the generated ms_tracker_result.h
 * (mstrack.fixed.vhdl_pkg.result_layout / result_layout_v2, default generics).  Both cores: the paper
 * core (PRESET 0, result word v1: mstrack_read_result) and core v2 (PRESET 1, result word v2:
 * mstrack_read_result_v2); mstrack_init records which (VERSION.result_version, dev->result_version).
 * C99, no allocation, no libc beyond
 * <stdint.h> / <stddef.h>.  Every register access is one aligned 32-bit volatile load or store
 * (never through the generated packed struct, which a compiler may split into byte accesses:
 * RES_HEAD has a read side effect).  Compiled with -DMSTRACK_IO_EXTERN, every access goes through
 * mstrack_io_read32 / mstrack_io_write32 instead, which the platform provides (a bus bridge, a
 * Linux UIO mapping, or the co-simulation harness tools/hdl/drv_main.cpp, whose accesses are
 * AXI4-Lite transactions on the simulated core).
 *
 * Typical use (docs/integration.md):
 *     mstrack_dev_t dev;
 *     if (mstrack_init(&dev, 0x43C00000u, 640, 480) != MSTRACK_OK) ... ;
 *     mstrack_start(&dev, x, y, w, h, MSTRACK_IRQ_RESULT | MSTRACK_IRQ_LOST);
 *     ... in the interrupt: mstrack_irq_handler(&dev, &res);
 *
 * A multi-target core (MAX_TARGETS >= 1: dev->max_targets after mstrack_init):
 *     mstrack_enable(&dev, MSTRACK_IRQ_ALL);
 *     mstrack_add(&dev, x, y, w, h, &id);     ... at any frame, as targets appear
 *     mstrack_remove(&dev, id);               ... as they leave
 *     ... in the interrupt: mstrack_irq_handler(&dev, NULL) reads every target's word of the frame
 *         into dev->target[id] for the ids in dev->target_mask.
 */
#ifndef MSTRACK_DRV_H
#define MSTRACK_DRV_H

#include <stddef.h>
#include <stdint.h>

#include "ms_tracker_regs.h"
#include "ms_tracker_result.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef MSTRACK_IO_EXTERN
/* one aligned 32-bit register read / write at byte address addr (base + offset) */
uint32_t mstrack_io_read32(uintptr_t addr);
void mstrack_io_write32(uintptr_t addr, uint32_t value);
#endif

#define MSTRACK_MAGIC 0x4D53544Bu          /* ID register ("MSTK") */
#define MSTRACK_MAP_MAJOR 1u               /* register map major version this driver knows */

/* return codes */
#define MSTRACK_OK 0
#define MSTRACK_ERR_ID (-1)                /* no mstrack core at this address */
#define MSTRACK_ERR_VERSION (-2)           /* register map or result word version unknown */
#define MSTRACK_ERR_ARG (-3)               /* argument out of range */
#define MSTRACK_NO_RESULT (-4)             /* no result since reset */
#define MSTRACK_ERR_FULL (-5)              /* multi-target: add refused, no free target slot */
#define MSTRACK_ERR_TIMEOUT (-6)           /* multi-target: a command not reported in MSTRACK_CMD_POLLS reads */
#define MSTRACK_ERR_SINGLE (-7)            /* a multi-target call on a single-target core */
#define MSTRACK_ERR_TORN (-8)              /* frames completed during every try of mstrack_read_frame */

#define MSTRACK_MAX_TARGETS 16u            /* target ids 0 .. 15 (MULTI.max_targets of the core: fewer) */
#ifndef MSTRACK_CMD_POLLS
#define MSTRACK_CMD_POLLS 100000u          /* CMD_STATUS reads before a command is given up */
#endif

/* interrupt bits (INT_STATUS / INT_ENABLE) */
#define MSTRACK_IRQ_RESULT MS_TRACKER_REGS__INT_STATUS__RESULT_bm
#define MSTRACK_IRQ_LOST MS_TRACKER_REGS__INT_STATUS__LOST_bm
#define MSTRACK_IRQ_ERROR MS_TRACKER_REGS__INT_STATUS__ERROR_bm
#define MSTRACK_IRQ_REACQUIRED MS_TRACKER_REGS__INT_STATUS__REACQUIRED_bm   /* core v2 only */
#define MSTRACK_IRQ_COMMAND MS_TRACKER_REGS__INT_STATUS__COMMAND_bm         /* multi-target only */
#define MSTRACK_IRQ_ALL (MSTRACK_IRQ_RESULT | MSTRACK_IRQ_LOST | MSTRACK_IRQ_ERROR | MSTRACK_IRQ_REACQUIRED | \
                         MSTRACK_IRQ_COMMAND)

/* status of result word v2 (RES_STATE.status): MSTRACK_STATUS_* in the generated ms_tracker_result.h */

/* One result, every field of result word v1, as integers (fixed-point formats in comments;
 * FORMAT register / MSTRACK_CF, MSTRACK_RHO_OUT_FRAC, MSTRACK_AF give the fraction bits). */
typedef struct {
    uint32_t valid;        /* 1: a result exists (RES_HEAD.valid; 1 for a decoded word) */
    uint32_t frame_count;  /* frames seen by the core since reset, mod 2**16 */
    uint32_t flags;        /* MSTRACK_FLAG_* bits */
    uint32_t err_code;     /* stream error code when flags & MSTRACK_FLAG_ERROR */
    uint32_t cx, cy;       /* target centre, unsigned Q.CF px (0-based pixel index) */
    uint32_t rho_c, rho_e; /* Bhattacharyya coefficients, Q.RHO_OUT_FRAC */
    uint32_t alpha_c;      /* colour weight of the fusion, Q.AF */
    uint32_t iter_c, iter_e; /* mean-shift iterations per feature */
    uint32_t stop_c, stop_e; /* stop codes: 0 shift, 1 rho, 2 max_iter, 3 lost */
    uint32_t box_w, box_h; /* target box size (px) */
} mstrack_result_t;

/* One result of core v2, every field of result word v2 (result_layout_v2): cx, cy Q.CF px; w8, h8
 * box size Q.8 px; rho, confidence Q1.16; status MSTRACK_STATUS_*; iter, stop of the winning mean
 * shift; decim_log2 log2 of the decimation; searched start points besides the centre; flags,
 * err_code, frame_count as v1; valid as v1 (1 for a decoded word). */
typedef struct {
    uint32_t cx, cy, w8, h8, rho, confidence, status, iter, stop, decim_log2, searched;
    uint32_t flags, err_code, frame_count;
    uint32_t valid;
    uint32_t target_id;    /* multi-target cores: the target (RES_HEAD.target_id); else 0 */
} mstrack_result_v2_t;

typedef struct {
    uintptr_t base;        /* byte address of the register block */
    uint32_t irq_mask;     /* interrupts enabled by mstrack_start */
    uint32_t irq_count;    /* handler calls that found a status bit set */
    uint32_t result_version; /* 1 paper core (result word v1), 2 core v2 (mstrack_init sets it) */
    mstrack_result_t last; /* filled by mstrack_irq_handler on a result interrupt (v2: the common fields) */
    mstrack_result_v2_t last_v2; /* v2: filled by mstrack_irq_handler on a result interrupt */
    /* multi-target cores (max_targets >= 1) */
    uint32_t max_targets;  /* MULTI.max_targets: target slots; 0 a single-target core */
    uint32_t target_mask;  /* ids with a word in the last frame read (mstrack_read_frame) */
    uint32_t box_rejected; /* ids whose add box the core rejected (CMD_STATUS code 3 seen by the handler) */
    uint32_t add_refused;  /* ids whose add the capacity rule refused at its frame (CMD_STATUS code 2 seen by
                              the handler; cores with MULTI.shared_engine) */
    uint32_t shared_engine; /* MULTI.shared_engine: one engine serves every target (mstrack_init sets it) */
    mstrack_result_v2_t target[MSTRACK_MAX_TARGETS]; /* the last frame's word of each id in target_mask */
} mstrack_dev_t;

/* Check ID and versions (map major 1, result word 1 or 2: dev->result_version), disable the core,
 * clear interrupts and counters, set the frame size.
 * Returns MSTRACK_OK, MSTRACK_ERR_ID, MSTRACK_ERR_VERSION or MSTRACK_ERR_ARG (size < 3 or
 * width > FORMAT.max_frame_w). */
int mstrack_init(mstrack_dev_t *dev, uintptr_t base, uint32_t width, uint32_t height);

/* Give the init box (0-based px; x, y may be negative), enable the interrupts in irq_mask
 * (MSTRACK_IRQ_*) and the core.  The box applies from the next frame. */
int mstrack_start(mstrack_dev_t *dev, int32_t x, int32_t y, uint32_t w, uint32_t h, uint32_t irq_mask);

/* Enable the interrupts in irq_mask and the core, without an init box (a multi-target core gets its
 * targets from mstrack_add). */
void mstrack_enable(mstrack_dev_t *dev, uint32_t irq_mask);

/* Multi-target cores: add a target with the box (0-based px; x, y may be negative).  The core takes it
 * between frames (from the next frame); waits for the report (polling CMD_STATUS) and gives the
 * target's id.  Returns MSTRACK_OK, MSTRACK_ERR_FULL (no free slot), MSTRACK_ERR_ARG,
 * MSTRACK_ERR_TIMEOUT or MSTRACK_ERR_SINGLE.  A box the core rejects later (it does not clip into the
 * frame) is reported by the handler in dev->box_rejected, and its id is free again.  On a core with one
 * engine for every target (dev->shared_engine), an add whose job would not fit its frame is refused at
 * that frame: the handler reports it in dev->add_refused, and its id is free again.  CMD_STATUS keeps
 * the last report only: give at most one add per frame where such a report must not be missed. */
int mstrack_add(mstrack_dev_t *dev, int32_t x, int32_t y, uint32_t w, uint32_t h, uint32_t *id);

/* Multi-target cores: remove target id (between frames).  Returns MSTRACK_OK, MSTRACK_ERR_ARG (id not
 * live), MSTRACK_ERR_TIMEOUT or MSTRACK_ERR_SINGLE. */
int mstrack_remove(mstrack_dev_t *dev, uint32_t id);

/* Multi-target cores: the slots holding a target (MULTI.live, bit k: id k). */
uint32_t mstrack_live(const mstrack_dev_t *dev);

/* Multi-target cores: read target id's word of the last complete frame (RES_SEL, then RES_HEAD first,
 * then every field).  Returns MSTRACK_OK or MSTRACK_NO_RESULT. */
int mstrack_read_target(const mstrack_dev_t *dev, uint32_t id, mstrack_result_v2_t *r);

/* Multi-target cores: read the last complete frame: RES_MASK into dev->target_mask and each of its
 * targets' words into dev->target[id].  Every word must carry RES_MASK's frame_count, else (a frame
 * completed meanwhile) it reads again, 3 tries.  Returns MSTRACK_OK, MSTRACK_ERR_TORN or
 * MSTRACK_ERR_SINGLE. */
int mstrack_read_frame(mstrack_dev_t *dev);

/* Stop feeding frames to the core (the frame in progress completes); interrupts off. */
void mstrack_stop(mstrack_dev_t *dev);

/* Read the last result: RES_HEAD first (it snapshots the result), then every field.
 * Returns MSTRACK_OK or MSTRACK_NO_RESULT (r->valid = 0).  On core v2 the registers of v1-only
 * fields read 0 (rho_e, alpha_c, iter_*, stop_*, box_*) and rho_c holds rho: use mstrack_read_result_v2. */
int mstrack_read_result(const mstrack_dev_t *dev, mstrack_result_t *r);

/* Core v2: read the last result, RES_HEAD first, then every field of result word v2.
 * Returns MSTRACK_OK or MSTRACK_NO_RESULT (r->valid = 0). */
int mstrack_read_result_v2(const mstrack_dev_t *dev, mstrack_result_v2_t *r);

/* Read the raw result word of the snapshot taken by the last RES_HEAD read (5 x 32 bits, LSB first). */
void mstrack_read_raw(const mstrack_dev_t *dev, uint32_t words[5]);

/* Decode a result word v1 (words LSB first, MSTRACK_RESULT_WORDS of them) with the layout of
 * ms_tracker_result.h; sets r->valid = 1. */
void mstrack_decode_word(const uint32_t *words, mstrack_result_t *r);

/* Decode a result word v2 (5 words LSB first); sets r->valid = 1. */
void mstrack_decode_word_v2(const uint32_t *words, mstrack_result_v2_t *r);

/* Interrupt handler: reads INT_STATUS, on a result reads it into dev->last (and *r if not NULL),
 * (a multi-target core: mstrack_read_frame, every target's word; dev->last is not touched; on a
 * command report with code 3 the id goes into dev->box_rejected),
 * clears the bits it saw (W1C) and returns them (0: not ours).  Core v2 (dev->result_version 2):
 * the result is read with mstrack_read_result_v2 into dev->last_v2, and dev->last (*r) gets the
 * fields common to both words (valid, frame_count, flags, err_code, cx, cy; rho_c = rho; the rest 0). */
uint32_t mstrack_irq_handler(mstrack_dev_t *dev, mstrack_result_t *r);

/* Counters (RESULT_COUNT .. DROP_COUNT) and their clear. */
typedef struct {
    uint32_t results, lost, errors, rejected, dropped;
} mstrack_counters_t;
void mstrack_read_counters(const mstrack_dev_t *dev, mstrack_counters_t *c);
void mstrack_clear_counters(const mstrack_dev_t *dev);

#ifdef __cplusplus
}
#endif

#endif
