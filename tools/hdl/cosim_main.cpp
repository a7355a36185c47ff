// cosim_main.cpp: Verilator C++ co-simulation harness of ms_tracker (no cocotb, no Python per cycle).
//
// Built and driven by mstrack.hw.fastsim (docs/performance.md, "Real-time check (1080p60)"): the
// GHDL netlist of ms_tracker (generics baked in) is verilated with --prefix Vms_tracker and
// linked with this file.  It resets the core, gives the init box on s_init_*, streams the
// frames on s_axis_* (PPC pixels per clock, pixel k in tdata bits 24k+23 .. 24k, tuser on each
// frame's first beat, tlast on each line's last beat) with programmable blanking (tvalid low)
// after every line and after
// every frame, takes the result words on m_axis_result_* (optionally with random
// back-pressure), and writes, per frame and per result, the cycles at which things happened.
//
//   Vcosim job.txt out.txt
//
// job.txt: one "key value" per line ('#' starts a comment line):
//   width, height     frame size (px); frame_width/frame_height ports
//   ppc               pixels per beat, the core's PPC generic (default 1); width a multiple of it
//   frames            number of frames in the pixel file
//   pixels            path of the pixel file: frames x height x width little-endian uint32,
//                     R << 16 | G << 8 | B (mstrack.hw.cosim.frame_words)
//   init              1: give the init box before the first frame (default 1)
//   init_x, init_y    init box, two's complement already masked to the port width by the caller
//   init_w, init_h    init box size
//   hblank            tvalid-low clocks after each line's last pixel (default 0)
//   vblank            extra tvalid-low clocks after each frame's last line (default 0)
//   lead              tvalid-low clocks between the init and the first pixel (default 0)
//   in_pause_pct      random extra tvalid-low clocks on the input, percent (default 0)
//   out_pause_pct     random m_axis_result_tready = 0, percent (default 0)
//   seed              seed of both pause generators (default 1)
//   results           results to wait for (default: frames)
//   watchdog          abort when a frame's result has not come this many clocks after its last
//                     pixel, or when the input stalls this many clocks in a row (default 4e6)
//   tail              clocks to run after the last expected result, to catch extra results
//   reset_cycles      clocks of rst = 1 at the start (default 5)
//   max_cycles        hard limit on the clocks simulated (default: none)
//
// out.txt, one record per line:
//   F <frame> <first_pixel_cycle> <last_pixel_cycle> <stall_cycles>
//   R <index> <result word, hex, MSB first> <valid_cycle> <taken_cycle>
//   E <status: done | watchdog_result | watchdog_stall | max_cycles> <cycles> <seconds> <cpu_seconds> <detail>
// A cycle number c is the clock edge (counted from 0 after reset) at which a handshake
// happened (tvalid = tready = 1 sampled at that edge); valid_cycle is the first edge at which
// the result word was valid, taken_cycle the edge at which it was taken.  stall_cycles
// counts the edges of that frame with s_axis_tvalid = 1 and s_axis_tready = 0.  seconds is
// the wall time of the simulation loop, cpu_seconds its CPU time (the fair measure on a
// loaded machine).  Prints "cycles N seconds S cpu_seconds C cycles_per_s R status X" on
// stdout; exit code 0 when done, 3 on a watchdog or the cycle limit, 2 on bad arguments.
#include "Vms_tracker.h"
#include "verilated.h"
#include "harness_job.h"

#include <chrono>
#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using harness::hex_of;

// Drive a tdata port with ppc 24-bit pixels, pixel k at bits 24k+23 .. 24k: a scalar port
// (PPC 1, 2: up to 48 bits) or a VlWide (PPC 4: 96 bits in 32-bit words, LSB first).
template <std::size_t N>
void set_pixels(VlWide<N>& port, const uint32_t* p, int ppc) {
    uint32_t w[N] = {};
    for (int k = 0; k < ppc; ++k) {
        const uint64_t v = p[k] & 0xFFFFFFu;
        const int bit = 24 * k;
        const std::size_t i = static_cast<std::size_t>(bit / 32);
        const int sh = bit % 32;
        const uint64_t wide = v << sh;
        if (i < N) w[i] |= static_cast<uint32_t>(wide);
        if (i + 1 < N) w[i + 1] |= static_cast<uint32_t>(wide >> 32);
    }
    for (std::size_t i = 0; i < N; ++i) port[i] = w[i];
}

template <typename T>
void set_pixels(T& port, const uint32_t* p, int ppc) {
    uint64_t v = 0;
    for (int k = 0; k < ppc; ++k) v |= static_cast<uint64_t>(p[k] & 0xFFFFFFu) << (24 * k);
    port = static_cast<T>(v);
}

std::string hex_of(uint64_t v) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

struct FrameRec {
    long long first = -1, last = -1, stalls = 0;
};

struct ResultRec {
    std::string word;
    long long valid = -1, taken = -1;
};

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s job.txt out.txt\n", argv[0]);
        return 2;
    }
    // ------------------------------------------------------------------ job
    harness::Job job;
    if (!harness::read_job(argv[1], job)) return 2;
    auto num = [&](const char* k, long long d) -> long long { return job.num(k, d); };
    const long long W = num("width", 0), H = num("height", 0), n_frames = num("frames", 0);
    const long long ppc = num("ppc", 1);
    if (W < 3 || H < 3 || n_frames < 0 || !job.has("pixels") || !(ppc == 1 || ppc == 2 || ppc == 4) ||
        W % ppc != 0) {
        std::fprintf(stderr, "job needs width, height (>= 3), frames and pixels; ppc 1, 2, 4 dividing width\n");
        return 2;
    }
    const long long hblank = num("hblank", 0), vblank = num("vblank", 0), lead = num("lead", 0);
    const int in_pause = static_cast<int>(num("in_pause_pct", 0));
    const int out_pause = static_cast<int>(num("out_pause_pct", 0));
    const long long n_results = num("results", n_frames);
    const long long watchdog = num("watchdog", 4000000);
    const long long tail = num("tail", 200);
    const long long max_cycles = num("max_cycles", -1);
    const bool do_init = num("init", 1) != 0;

    std::FILE* pix_f = std::fopen(job.str("pixels").c_str(), "rb");
    if (!pix_f) {
        std::fprintf(stderr, "cannot read pixels %s\n", job.str("pixels").c_str());
        return 2;
    }
    std::vector<uint32_t> pix(static_cast<std::size_t>(W * H));
    auto load_frame = [&]() -> bool {
        return std::fread(pix.data(), 4, pix.size(), pix_f) == pix.size();
    };

    // ------------------------------------------------------------------ model
    VerilatedContext ctx;
    ctx.randReset(0);
    Vms_tracker top{&ctx};
    std::mt19937_64 rng(static_cast<uint64_t>(num("seed", 1)));
    std::uniform_int_distribution<int> pct(0, 99);

    top.frame_width = static_cast<uint32_t>(W);
    top.frame_height = static_cast<uint32_t>(H);
    top.s_init_tvalid = 0;
    top.s_init_x = static_cast<uint32_t>(num("init_x", 0));
    top.s_init_y = static_cast<uint32_t>(num("init_y", 0));
    top.s_init_w = static_cast<uint32_t>(num("init_w", 0));
    top.s_init_h = static_cast<uint32_t>(num("init_h", 0));
    top.s_axis_tvalid = 0;
    {
        const uint32_t zeros[4] = {0, 0, 0, 0};
        set_pixels(top.s_axis_tdata, zeros, static_cast<int>(ppc));
    }
    top.s_axis_tlast = 0;
    top.s_axis_tuser = 0;
    top.m_axis_result_tready = 0;
    top.rst = 1;
    top.clk = 0;
    top.eval();
    for (long long c = 0; c < num("reset_cycles", 5); ++c) {
        top.clk = 1; top.eval();
        top.clk = 0; top.eval();
    }
    top.rst = 0;

    // ------------------------------------------------------------------ stimulus state
    std::vector<FrameRec> frames(static_cast<std::size_t>(n_frames));
    std::vector<ResultRec> results;
    results.reserve(static_cast<std::size_t>(n_results + 8));
    bool init_pending = do_init;
    long long f = 0, x = 0, y = 0;          // next pixel to send
    long long blank = 0;                    // tvalid-low clocks still to insert
    bool holding = false;                   // a beat is offered and not yet taken (must stay)
    bool frame_loaded = false;
    bool result_seen = false;               // the current output word was already valid
    long long stall_run = 0, done_at = -1;
    std::string status = "done", detail;

    auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    long long cycle = 0;
    for (;; ++cycle) {
        if (max_cycles >= 0 && cycle >= max_cycles) {
            status = "max_cycles";
            break;
        }
        // ---- inputs of this clock
        bool s_valid = false;
        top.s_init_tvalid = init_pending;
        if (init_pending) {
            // no pixels before the init box is taken
        } else if (blank > 0) {
            --blank;
        } else if (f < n_frames) {
            if (!frame_loaded) {
                if (!load_frame()) {
                    status = "bad_pixels";
                    detail = "pixel file too short at frame " + std::to_string(f);
                    break;
                }
                frame_loaded = true;
            }
            // a beat once offered stays until taken (AXI4-Stream); pauses only between beats
            s_valid = holding || !(in_pause && pct(rng) < in_pause);
            if (s_valid) {
                set_pixels(top.s_axis_tdata, &pix[static_cast<std::size_t>(y * W + x)], static_cast<int>(ppc));
                top.s_axis_tuser = (x == 0 && y == 0);
                top.s_axis_tlast = (x == W - ppc);
            }
        }
        top.s_axis_tvalid = s_valid;
        top.m_axis_result_tready = !(out_pause && pct(rng) < out_pause);
        top.clk = 0;
        top.eval();  // settle the ready/valid outputs with this clock's inputs

        // ---- handshakes at this clock's rising edge
        if (init_pending && top.s_init_tready) {
            init_pending = false;
            blank = lead;
        }
        const bool s_fire = s_valid && top.s_axis_tready;
        if (top.m_axis_result_tvalid) {
            if (!result_seen) {
                results.push_back(ResultRec{});
                results.back().valid = cycle;
                result_seen = true;
            }
            if (top.m_axis_result_tready) {
                results.back().word = hex_of(top.m_axis_result_tdata);
                results.back().taken = cycle;
                result_seen = false;
            }
        }
        top.clk = 1;
        top.eval();

        // ---- bookkeeping after the edge
        if (s_valid && !s_fire) {
            ++frames[f].stalls;
            holding = true;
            if (++stall_run > watchdog) {
                status = "watchdog_stall";
                detail = "frame " + std::to_string(f) + " pixel (" + std::to_string(x) + ", " +
                         std::to_string(y) + ") not accepted for " + std::to_string(stall_run) + " clocks";
                ++cycle;
                break;
            }
        } else {
            stall_run = 0;
        }
        if (s_fire) {
            holding = false;
            if (x == 0 && y == 0) frames[f].first = cycle;
            if (x == W - ppc) {
                blank = hblank;
                x = 0;
                if (++y == H) {
                    frames[f].last = cycle;
                    blank += vblank;
                    y = 0;
                    ++f;
                    frame_loaded = false;
                }
            } else {
                x += ppc;
            }
        }
        // result watchdog: the oldest frame without a result
        long long taken = static_cast<long long>(results.size()) - (result_seen ? 1 : 0);
        if (taken < f && taken < n_frames && frames[taken].last >= 0 && cycle - frames[taken].last > watchdog) {
            status = "watchdog_result";
            detail = "no result for frame " + std::to_string(taken) + " within " + std::to_string(watchdog) +
                     " clocks of its last pixel";
            ++cycle;
            break;
        }
        if (done_at < 0 && f >= n_frames && !init_pending && taken >= n_results) done_at = cycle;
        if (done_at >= 0 && cycle - done_at >= tail) {
            ++cycle;
            break;
        }
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu_secs = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    top.final();
    std::fclose(pix_f);

    // ------------------------------------------------------------------ report
    std::FILE* o = std::fopen(argv[2], "w");
    if (!o) {
        std::fprintf(stderr, "cannot write %s\n", argv[2]);
        return 2;
    }
    for (std::size_t i = 0; i < frames.size(); ++i) {
        if (frames[i].first < 0 && frames[i].stalls == 0) continue;
        std::fprintf(o, "F %zu %lld %lld %lld\n", i, frames[i].first, frames[i].last, frames[i].stalls);
    }
    for (std::size_t i = 0; i < results.size(); ++i) {
        if (results[i].taken < 0) continue;  // valid but never taken (run ended)
        std::fprintf(o, "R %zu %s %lld %lld\n", i, results[i].word.c_str(), results[i].valid, results[i].taken);
    }
    std::fprintf(o, "E %s %lld %.6f %.6f %s\n", status.c_str(), cycle, secs, cpu_secs, detail.c_str());
    std::fclose(o);
    std::printf("cycles %lld seconds %.6f cpu_seconds %.6f cycles_per_s %.0f status %s\n", cycle, secs,
                cpu_secs, secs > 0 ? cycle / secs : 0.0, status.c_str());
    return status == "done" ? 0 : 3;
}
