// drv_main.cpp: the C driver sw/mstrack_drv.c running against ms_tracker_axi under Verilator.
//
// Built and driven by mstrack.hw.fastsim.simulate_driver (docs/integration.md, "The driver against
// the RTL"): the GHDL netlist of ms_tracker_axi (generics baked in) is verilated with --prefix
// Vms_tracker_axi and linked with this file and sw/mstrack_drv.c compiled with -DMSTRACK_IO_EXTERN,
// so that each of the driver's register accesses is one AXI4-Lite transaction on the simulated
// core (mstrack_io_read32 / mstrack_io_write32 below), clocked together with the video.
//
// What runs is what a bare-metal integration does: mstrack_init (ID, versions, frame size),
// mstrack_start (init box, interrupts, enable), then the video streams (s_axis_*, with
// programmable blanking) and whenever the core's irq output is high the driver's interrupt handler
// mstrack_irq_handler runs, reads the result through the registers, clears the bits it saw, and
// the harness records the result as the driver decoded it and the raw word (mstrack_read_raw).
// At the end: mstrack_read_counters, mstrack_stop.  The video does not wait for the CPU: pixels
// stream during the driver's bus transactions, as on a chip.
//
//   Vdrv job.txt out.txt
//
// job.txt, one "key value" per line ('#' starts a comment line):
//   width, height     frame size (px), given to mstrack_init
//   frames, pixels    number of frames; pixel file (frames x height x width little-endian uint32,
//                     R << 16 | G << 8 | B: mstrack.hw.cosim.frame_words)
//   init_x, init_y    init box for mstrack_start (signed), init_w, init_h its size
//   irq_mask          interrupts enabled by mstrack_start (MSTRACK_IRQ_*, default all)
//   hblank, vblank    tvalid-low clocks after each line / extra after each frame (default 0)
//   io_gap            idle clocks before each register access (a slower CPU; default 0)
//   results           results to wait for (default: frames)
//   watchdog          stop when a frame's result has not been read this many clocks after its last
//                     pixel, or a bus transaction has not completed in 10,000 clocks (default 4e6)
//   tail              clocks to run after the last expected result (default 200)
//   result_gap        a core built with RESULT_STREAM: a sink on m_axis_result that holds tready low
//                     for this many clocks after each beat it takes (-1, default: tready always 1, no
//                     T records); its beats are written as T records
//   multi             1: a multi-target core (ms_tracker_axi MAX_TARGETS >= 1): no init box; the
//                     driver's mstrack_enable, then the op lines; each result interrupt reads every
//                     target's word of the frame (mstrack_read_frame)
//   op F add L X Y W H  (multi, several lines) mstrack_add of target label L with box X Y W H, called
//                     once the result of frame F-1 has been read (F = 0: before the video starts)
//   op F remove L     (multi) mstrack_remove of the id that label L's add returned
//
// out.txt, one record per line:
//   D <call> <return code>                          mstrack_init / mstrack_start
//   R <index> <raw word, hex, MSB first> <irq bits> <irq_cycle> <handled_cycle> <key=value ...>
//                                                   one per handler call that saw a result: the
//                                                   driver's decoded fields (mstrack_result_v2_t
//                                                   for result word v2, mstrack_result_t for v1)
//   M <index> <mask> <irq bits> <irq_cycle> <handled_cycle> <frame_count> <box_rejected> <add_refused>
//                                                   multi: one per result interrupt: the driver's
//                                                   dev.target_mask, RES_MASK's frame_count, the
//                                                   driver's dev.box_rejected and dev.add_refused
//                                                   after the handler
//   W <index> <id> <raw word, hex> <key=value ...>  multi: each target of that frame: the driver's
//                                                   dev.target[id] and the raw word (read again
//                                                   with mstrack_read_target, mstrack_read_raw)
//   A <label> <rc> <id> <started before> <started after>
//                                                   multi: mstrack_add's return code and id, and the
//                                                   frames whose first pixel had been taken before
//                                                   the call and at its return
//   X <label> <rc> <started before> <started after> multi: mstrack_remove
//   J <box_rejected> <live> <add_refused> <shared_engine>
//                                                   multi, at the end: dev.box_rejected, mstrack_live,
//                                                   dev.add_refused, dev.shared_engine
//   Q <irq bits> <cycle>                            a handler call without a result bit
//   T <tlast> <tdata, hex, MSB first> <cycle>       result_gap >= 0: each beat the sink took
//   C results lost errors rejected dropped          mstrack_read_counters at the end
//   B <bus errors>                                  SLVERR answers seen by the driver's accesses
//   E <status: done | watchdog_result | bus_timeout | driver_error> <cycles> <seconds> <detail>
// Exit code 0 when done, 3 otherwise, 2 on bad arguments.
#include "Vms_tracker_axi.h"
#include "verilated.h"
#include "harness_job.h"

extern "C" {
#include "mstrack_drv.h"
}

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// The simulation: the core, the video source and the clock; one object, used by the driver's
// register accessors through the pointer `sim`.
struct Sim {
    Vms_tracker_axi* top = nullptr;
    long long cycle = 0;
    // video
    long long W = 0, H = 0, n_frames = 0, hblank = 0, vblank = 0;
    std::FILE* pix_f = nullptr;
    std::vector<uint32_t> pix;
    bool video_on = false, frame_loaded = false, holding = false;
    long long f = 0, x = 0, y = 0, blank = 0;
    std::vector<long long> last_pixel;       // cycle of each frame's last pixel
    long long started = 0;                   // frames whose first pixel has been taken
    bool bad_pixels = false;
    // result stream sink (result_gap >= 0)
    long long result_gap = -1, r_hold = 0;
    std::vector<std::string> beats;          // "T ..." records
    // bus
    long long io_gap = 0, bus_errors = 0;
    bool bus_timeout = false;

    struct Edge {
        bool aw = false, w = false, b = false, ar = false, r = false;
        uint32_t rdata = 0;
        unsigned rresp = 0, bresp = 0;
    };

    // One clock: the video's inputs, the handshakes sampled before the rising edge, the edge.
    Edge tick() {
        bool s_valid = false;
        if (video_on && blank > 0) {
            --blank;
        } else if (video_on && f < n_frames) {
            if (!frame_loaded) {
                if (std::fread(pix.data(), 4, pix.size(), pix_f) != pix.size()) {
                    bad_pixels = true;
                } else {
                    frame_loaded = true;
                }
            }
            s_valid = frame_loaded;
            if (s_valid) {
                top->s_axis_tdata = pix[static_cast<std::size_t>(y * W + x)] & 0xFFFFFFu;
                top->s_axis_tuser = (x == 0 && y == 0);
                top->s_axis_tlast = (x == W - 1);
            }
        }
        top->s_axis_tvalid = s_valid;
        if (result_gap >= 0) top->m_axis_result_tready = (r_hold == 0);
        top->clk = 0;
        top->eval();
        const bool r_fire = result_gap >= 0 && top->m_axis_result_tvalid && top->m_axis_result_tready;
        if (r_fire) {
            beats.push_back("T " + std::to_string(static_cast<int>(top->m_axis_result_tlast)) + " " +
                            harness::hex_of(top->m_axis_result_tdata) + " " + std::to_string(cycle));
        }
        Edge e;
        e.aw = top->s_axil_awvalid && top->s_axil_awready;
        e.w = top->s_axil_wvalid && top->s_axil_wready;
        e.b = top->s_axil_bvalid && top->s_axil_bready;
        e.ar = top->s_axil_arvalid && top->s_axil_arready;
        e.r = top->s_axil_rvalid && top->s_axil_rready;
        e.rdata = top->s_axil_rdata;
        e.rresp = top->s_axil_rresp;
        e.bresp = top->s_axil_bresp;
        const bool s_fire = s_valid && top->s_axis_tready;
        top->clk = 1;
        top->eval();
        if (r_fire) {
            r_hold = result_gap;
        } else if (r_hold > 0) {
            --r_hold;
        }
        if (s_fire) {
            if (x == 0 && y == 0) ++started;
            if (x == W - 1) {
                blank = hblank;
                x = 0;
                if (++y == H) {
                    last_pixel.push_back(cycle);
                    blank += vblank;
                    y = 0;
                    ++f;
                    frame_loaded = false;
                }
            } else {
                ++x;
            }
        }
        ++cycle;
        return e;
    }

    void idle(long long n) {
        for (long long i = 0; i < n; ++i) tick();
    }
};

Sim* sim = nullptr;
// RES_MASK's address and frame_count field (generated header)
constexpr uintptr_t MS_RES_MASK_ADDR = offsetof(ms_tracker_regs_t, RES_MASK);
inline uint32_t FIELD_RES_MASK_FC(uint32_t v) {
    return (v & MS_TRACKER_REGS__RES_MASK__FRAME_COUNT_bm) >> MS_TRACKER_REGS__RES_MASK__FRAME_COUNT_bp;
}
constexpr long long BUS_LIMIT = 10000;

std::string hex_words(const uint32_t w[5]) {
    std::string s;
    char buf[9];
    for (int i = 5; i-- > 0;) {
        std::snprintf(buf, sizeof buf, "%08x", static_cast<unsigned>(w[i]));
        s += buf;
    }
    return s;
}

}  // namespace

// The driver's register accessors (sw/mstrack_drv.h, MSTRACK_IO_EXTERN): one AXI4-Lite transaction
// each, the video streaming meanwhile.  A transaction that does not complete in BUS_LIMIT clocks
// marks the run (status bus_timeout) and returns 0, so the driver and the run end.
extern "C" uint32_t mstrack_io_read32(uintptr_t addr) {
    Vms_tracker_axi& t = *sim->top;
    sim->idle(sim->io_gap);
    t.s_axil_araddr = static_cast<uint32_t>(addr & 0xFFFu);
    t.s_axil_arprot = 0;
    t.s_axil_arvalid = 1;
    t.s_axil_rready = 1;
    for (long long n = 0; n < BUS_LIMIT && !sim->bus_timeout; ++n) {
        const Sim::Edge e = sim->tick();
        if (e.ar) t.s_axil_arvalid = 0;
        if (e.r) {
            t.s_axil_rready = 0;
            if (e.rresp != 0) ++sim->bus_errors;
            return e.rdata;
        }
    }
    t.s_axil_arvalid = 0;
    t.s_axil_rready = 0;
    sim->bus_timeout = true;
    return 0;
}

extern "C" void mstrack_io_write32(uintptr_t addr, uint32_t value) {
    Vms_tracker_axi& t = *sim->top;
    sim->idle(sim->io_gap);
    t.s_axil_awaddr = static_cast<uint32_t>(addr & 0xFFFu);
    t.s_axil_awprot = 0;
    t.s_axil_awvalid = 1;
    t.s_axil_wdata = value;
    t.s_axil_wstrb = 0xF;
    t.s_axil_wvalid = 1;
    t.s_axil_bready = 1;
    for (long long n = 0; n < BUS_LIMIT && !sim->bus_timeout; ++n) {
        const Sim::Edge e = sim->tick();
        if (e.aw) t.s_axil_awvalid = 0;
        if (e.w) t.s_axil_wvalid = 0;
        if (e.b) {
            t.s_axil_bready = 0;
            if (e.bresp != 0) ++sim->bus_errors;
            return;
        }
    }
    t.s_axil_awvalid = 0;
    t.s_axil_wvalid = 0;
    t.s_axil_bready = 0;
    sim->bus_timeout = true;
}

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s job.txt out.txt\n", argv[0]);
        return 2;
    }
    harness::Job job;
    if (!harness::read_job(argv[1], job, {"op"})) return 2;
    auto num = [&](const char* k, long long d) -> long long { return job.num(k, d); };
    Sim s;
    sim = &s;
    s.W = num("width", 0);
    s.H = num("height", 0);
    s.n_frames = num("frames", 0);
    if (s.W < 1 || s.H < 1 || s.n_frames < 0 || !job.has("pixels")) {
        std::fprintf(stderr, "job needs width, height, frames and pixels\n");
        return 2;
    }
    s.hblank = num("hblank", 0);
    s.vblank = num("vblank", 0);
    s.io_gap = num("io_gap", 0);
    s.result_gap = num("result_gap", -1);
    const long long n_results = num("results", s.n_frames);
    const long long watchdog = num("watchdog", 4000000);
    const long long tail = num("tail", 200);
    s.pix_f = std::fopen(job.str("pixels").c_str(), "rb");
    if (!s.pix_f) {
        std::fprintf(stderr, "cannot read pixels %s\n", job.str("pixels").c_str());
        return 2;
    }
    s.pix.resize(static_cast<std::size_t>(s.W * s.H));
    std::FILE* o = std::fopen(argv[2], "w");
    if (!o) {
        std::fprintf(stderr, "cannot write %s\n", argv[2]);
        return 2;
    }

    VerilatedContext ctx;
    ctx.randReset(0);
    Vms_tracker_axi top{&ctx};
    s.top = &top;
    top.s_axil_awvalid = top.s_axil_wvalid = top.s_axil_bready = 0;
    top.s_axil_arvalid = top.s_axil_rready = 0;
    top.s_axis_tvalid = top.s_axis_tlast = top.s_axis_tuser = 0;
    top.s_axis_tdata = 0;
    top.m_axis_result_tready = 1;
    top.rst = 1;
    s.idle(5);
    top.rst = 0;
    s.idle(2);

    std::string status = "done", detail;
    const auto t0 = std::chrono::steady_clock::now();
    const bool multi = num("multi", 0) != 0;
    struct Op {
        long long frame;
        bool add;
        std::string label;
        long long x = 0, y = 0, w = 0, h = 0;
    };
    std::vector<Op> ops;
    for (const auto& kv : job.lines) {
        std::istringstream ls(kv.second);
        Op op;
        std::string what;
        ls >> op.frame >> what >> op.label;
        op.add = what == "add";
        if (op.add) ls >> op.x >> op.y >> op.w >> op.h;
        if (!ls || (!op.add && what != "remove")) {
            std::fprintf(stderr, "bad op line: %s\n", kv.second.c_str());
            return 2;
        }
        ops.push_back(op);
    }
    std::map<std::string, uint32_t> ids;     // label -> the id its add returned
    std::size_t next_op = 0;
    static mstrack_dev_t dev;
    // the ops due before frame `frame` (called in the application's context, not the handler's)
    auto run_ops = [&](long long frame) {
        for (; next_op < ops.size() && ops[next_op].frame <= frame; ++next_op) {
            const Op& op = ops[next_op];
            const long long before = s.started;
            if (op.add) {
                uint32_t id = 0;
                const int r = mstrack_add(&dev, static_cast<int32_t>(op.x), static_cast<int32_t>(op.y),
                                          static_cast<uint32_t>(op.w), static_cast<uint32_t>(op.h), &id);
                if (r == MSTRACK_OK) ids[op.label] = id;
                std::fprintf(o, "A %s %d %u %lld %lld\n", op.label.c_str(), r, r == MSTRACK_OK ? id : 0u, before,
                             s.started);
            } else {
                const auto it = ids.find(op.label);
                const int r = mstrack_remove(&dev, it == ids.end() ? 15u : it->second);
                std::fprintf(o, "X %s %d %lld %lld\n", op.label.c_str(), r, before, s.started);
            }
        }
    };
    int rc = mstrack_init(&dev, 0, static_cast<uint32_t>(s.W), static_cast<uint32_t>(s.H));
    std::fprintf(o, "D init %d\n", rc);
    if (rc == MSTRACK_OK && multi) {
        mstrack_enable(&dev, static_cast<uint32_t>(num("irq_mask", MSTRACK_IRQ_ALL)));
        std::fprintf(o, "D start %d\n", dev.max_targets > 0 ? MSTRACK_OK : MSTRACK_ERR_SINGLE);
        if (dev.max_targets == 0) rc = MSTRACK_ERR_SINGLE;
        run_ops(0);
    } else if (rc == MSTRACK_OK) {
        rc = mstrack_start(&dev, static_cast<int32_t>(num("init_x", 0)), static_cast<int32_t>(num("init_y", 0)),
                           static_cast<uint32_t>(num("init_w", 0)), static_cast<uint32_t>(num("init_h", 0)),
                           static_cast<uint32_t>(num("irq_mask", MSTRACK_IRQ_ALL)));
        std::fprintf(o, "D start %d\n", rc);
    }
    if (rc != MSTRACK_OK) {
        status = "driver_error";
        detail = "driver returned " + std::to_string(rc);
    }
    s.video_on = true;
    long long n_read = 0, done_at = -1;
    while (status == "done") {
        if (s.bus_timeout) {
            status = "bus_timeout";
            detail = "a register access was not answered in " + std::to_string(BUS_LIMIT) + " clocks";
            break;
        }
        if (s.bad_pixels) {
            status = "bad_pixels";
            detail = "pixel file too short at frame " + std::to_string(s.f);
            break;
        }
        if (top.irq) {
            const long long irq_cycle = s.cycle;
            mstrack_result_t r;
            const uint32_t st = mstrack_irq_handler(&dev, &r);
            if ((st & MSTRACK_IRQ_RESULT) && multi) {
                uint32_t fc = FIELD_RES_MASK_FC(mstrack_io_read32(MS_RES_MASK_ADDR));
                std::fprintf(o, "M %lld %u %u %lld %lld %u %u %u\n", n_read, dev.target_mask, st, irq_cycle, s.cycle,
                             fc, dev.box_rejected, dev.add_refused);
                for (uint32_t id = 0; id < MSTRACK_MAX_TARGETS; ++id) {
                    if (!(dev.target_mask & (1u << id))) continue;
                    mstrack_result_v2_t again;
                    uint32_t raw[5];
                    (void)mstrack_read_target(&dev, id, &again);
                    mstrack_read_raw(&dev, raw);
                    const mstrack_result_v2_t& v = dev.target[id];
                    std::fprintf(o, "W %lld %u %s valid=%u cx=%u cy=%u w8=%u h8=%u rho=%u confidence=%u status=%u"
                                 " iter=%u stop=%u decim_log2=%u searched=%u flags=%u err_code=%u frame_count=%u"
                                 " target_id=%u again_frame_count=%u\n",
                                 n_read, id, hex_words(raw).c_str(), v.valid, v.cx, v.cy, v.w8, v.h8, v.rho,
                                 v.confidence, v.status, v.iter, v.stop, v.decim_log2, v.searched, v.flags, v.err_code,
                                 v.frame_count, v.target_id, again.frame_count);
                }
                ++n_read;
                run_ops(n_read);
            } else if (st & MSTRACK_IRQ_RESULT) {
                uint32_t raw[5];
                mstrack_read_raw(&dev, raw);
                std::fprintf(o, "R %lld %s %u %lld %lld", n_read, hex_words(raw).c_str(), st, irq_cycle, s.cycle);
                if (dev.result_version == 2u) {
                    const mstrack_result_v2_t& v = dev.last_v2;
                    std::fprintf(o, " valid=%u cx=%u cy=%u w8=%u h8=%u rho=%u confidence=%u status=%u iter=%u stop=%u"
                                 " decim_log2=%u searched=%u flags=%u err_code=%u frame_count=%u\n",
                                 v.valid, v.cx, v.cy, v.w8, v.h8, v.rho, v.confidence, v.status, v.iter, v.stop,
                                 v.decim_log2, v.searched, v.flags, v.err_code, v.frame_count);
                } else {
                    std::fprintf(o, " valid=%u cx=%u cy=%u rho_c=%u rho_e=%u alpha_c=%u iter_c=%u iter_e=%u stop_c=%u"
                                 " stop_e=%u flags=%u err_code=%u box_w=%u box_h=%u frame_count=%u\n",
                                 r.valid, r.cx, r.cy, r.rho_c, r.rho_e, r.alpha_c, r.iter_c, r.iter_e, r.stop_c,
                                 r.stop_e, r.flags, r.err_code, r.box_w, r.box_h, r.frame_count);
                }
                ++n_read;
            } else {
                std::fprintf(o, "Q %u %lld\n", st, irq_cycle);
                s.tick();
            }
        } else {
            s.tick();
        }
        const long long oldest = n_read;   // the oldest frame whose result has not been read
        if (oldest < static_cast<long long>(s.last_pixel.size()) &&
            s.cycle - s.last_pixel[static_cast<std::size_t>(oldest)] > watchdog) {
            status = "watchdog_result";
            detail = "no result read for frame " + std::to_string(oldest) + " within " + std::to_string(watchdog) +
                     " clocks of its last pixel";
            break;
        }
        if (done_at < 0 && s.f >= s.n_frames && n_read >= n_results) done_at = s.cycle;
        if (done_at >= 0 && s.cycle - done_at >= tail) break;
    }
    if (status == "done") {
        mstrack_counters_t c;
        mstrack_read_counters(&dev, &c);
        mstrack_stop(&dev);
        std::fprintf(o, "C %u %u %u %u %u\n", c.results, c.lost, c.errors, c.rejected, c.dropped);
        if (multi) std::fprintf(o, "J %u %u %u %u\n", dev.box_rejected, mstrack_live(&dev), dev.add_refused,
                                dev.shared_engine);
        if (s.bus_timeout) {
            status = "bus_timeout";
            detail = "a register access at the end was not answered";
        }
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& b : s.beats) std::fprintf(o, "%s\n", b.c_str());
    std::fprintf(o, "B %lld\n", s.bus_errors);
    std::fprintf(o, "E %s %lld %.6f %s\n", status.c_str(), s.cycle, secs, detail.c_str());
    std::fclose(o);
    top.final();
    std::fclose(s.pix_f);
    std::printf("cycles %lld seconds %.6f status %s\n", s.cycle, secs, status.c_str());
    return status == "done" ? 0 : 3;
}
