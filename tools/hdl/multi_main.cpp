// multi_main.cpp: Verilator co-simulation harness of ms_tracker_multi (several targets, commands).
//
// Built and driven by mstrack.hw.fastsim.simulate_multi: the GHDL netlist of ms_tracker_multi
// (generics baked in) is verilated with --prefix Vms_tracker_multi and linked with this file.  It
// resets the core, streams the frames on s_axis_* with programmable blanking, gives the job's
// commands on s_cmd_* before the frames they belong to (the video waits until each is taken), takes
// the result words on m_axis_result_* (optionally with random back-pressure) and records every word,
// every cmd_done report and the cycles.
//
//   Vmulti job.txt out.txt
//
// job.txt, one "key value" per line ('#' starts a comment line):
//   width, height, frames, pixels   as tools/hdl/cosim_main.cpp (frame_width / frame_height ports)
//   hblank, vblank                  tvalid-low clocks after each line / extra after each frame
//   lead                            tvalid-low clocks before the first frame, after its commands
//                                   (the vertical blanking a camera gives before it; default 0)
//   cmd_gap                         idle clocks after each command taken before the next one of the
//                                   same frame is given (a CPU that issues commands slowly; default 0)
//   out_pause_pct, seed             random m_axis_result_tready = 0 (percent), its seed
//   words                           result words to wait for
//   watchdog                        stop when no word has come for this many clocks after the last
//                                   frame (or the input stalls this long)
//   tail                            clocks to run after the last expected word (default 200)
//   cmd F OP ID X Y W H             a command given before frame F's first pixel (several lines in
//                                   order): OP 0 add (box X, Y, W, H; X, Y already masked to the port
//                                   width), 1 remove (ID)
//   fault F KIND                    a stream fault in frame F: short_line (row 5 three pixels short,
//                                   tlast on its last), cut (the frame ends after its first 700 beats;
//                                   the next frame's start of frame cuts it)
//
// out.txt, one record per line:
//   W <index> <word, hex, MSB first> <last> <cycle>    a result word taken
//   K <code> <id> <cycle>                             a cmd_done report
//   T <frame> <command index> <cycle>                  a command taken
//   F <frame> <first_pixel_cycle> <last_pixel_cycle> <stall_cycles>   per frame streamed, at the end
//   E <status: done | watchdog> <cycles> <seconds> <cpu_seconds> <detail>
// stall_cycles counts the clocks in which a pixel of that frame was offered (s_axis_tvalid = 1)
// and not taken (s_axis_tready = 0): the core back-pressuring the video.  seconds is the
// wall time of the simulation loop, cpu_seconds its CPU time.
#include "Vms_tracker_multi.h"
#include "verilated.h"
#include "harness_job.h"

#include <chrono>
#include <cstdint>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Cmd {
    long long frame, op, id, x, y, w, h;
};

struct FrameTimes {
    long long first = -1, last = -1, stalls = 0;
};

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s job.txt out.txt\n", argv[0]);
        return 2;
    }
    harness::Job job;
    if (!harness::read_job(argv[1], job, {"cmd", "fault"})) return 2;
    std::vector<Cmd> cmds;
    std::map<long long, std::string> faults;
    for (const auto& [k, v] : job.lines) {
        std::istringstream ls(v);
        if (k == "fault") {
            long long fr = 0;
            std::string kind;
            ls >> fr >> kind;
            faults[fr] = kind;
        } else {
            Cmd c{};
            ls >> c.frame >> c.op >> c.id >> c.x >> c.y >> c.w >> c.h;
            cmds.push_back(c);
        }
    }
    auto num = [&](const char* k, long long d) -> long long { return job.num(k, d); };
    const long long W = num("width", 0), H = num("height", 0), n_frames = num("frames", 0);
    if (W < 1 || H < 1 || n_frames < 0 || !job.has("pixels")) {
        std::fprintf(stderr, "job needs width, height, frames and pixels\n");
        return 2;
    }
    const long long hblank = num("hblank", 0), vblank = num("vblank", 0), cmd_gap = num("cmd_gap", 0);
    const int out_pause = static_cast<int>(num("out_pause_pct", 0));
    const long long n_words = num("words", 0), watchdog = num("watchdog", 4000000), tail = num("tail", 200);
    std::FILE* pix_f = std::fopen(job.str("pixels").c_str(), "rb");
    std::FILE* o = std::fopen(argv[2], "w");
    if (!pix_f || !o) {
        std::fprintf(stderr, "cannot open the pixel or the output file\n");
        return 2;
    }
    std::vector<uint32_t> pix(static_cast<std::size_t>(W * H));

    VerilatedContext ctx;
    ctx.randReset(0);
    Vms_tracker_multi top{&ctx};
    std::mt19937_64 rng(static_cast<uint64_t>(num("seed", 1)));
    std::uniform_int_distribution<int> pct(0, 99);
    top.frame_width = static_cast<uint32_t>(W);
    top.frame_height = static_cast<uint32_t>(H);
    top.s_cmd_tvalid = 0;
    top.s_axis_tvalid = top.s_axis_tlast = top.s_axis_tuser = 0;
    top.s_axis_tdata = 0;
    top.m_axis_result_tready = 0;
    top.rst = 1;
    top.clk = 0;
    top.eval();
    for (int c = 0; c < 5; ++c) {
        top.clk = 1; top.eval();
        top.clk = 0; top.eval();
    }
    top.rst = 0;

    long long f = 0, x = 0, y = 0, blank = num("lead", 0), n_got = 0, last_event = 0, done_at = -1, frame_beats = 0;
    auto fault_of = [&](long long fr) -> std::string {
        auto it = faults.find(fr);
        return it == faults.end() ? std::string() : it->second;
    };
    // the width of the current row: three pixels short on row 5 of a short_line frame
    auto row_w = [&]() -> long long { return (y == 5 && fault_of(f) == "short_line") ? W - 3 : W; };
    std::size_t next_cmd = 0;
    long long cmd_wait = 0;                     // cmd_gap clocks left before the next command
    bool frame_loaded = false;
    std::string status = "done", detail;
    std::vector<FrameTimes> times(static_cast<std::size_t>(n_frames));
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    long long cycle = 0;
    for (;; ++cycle) {
        // ---- inputs of this clock: a command of the next frame first, then the video
        bool cmd_valid = false, s_valid = false;
        const bool at_frame_start = (x == 0 && y == 0);
        const bool cmd_due = next_cmd < cmds.size() && at_frame_start && cmds[next_cmd].frame <= f;
        if (cmd_due && cmd_wait > 0) {
            --cmd_wait;
        } else if (cmd_due) {
            const Cmd& c = cmds[next_cmd];
            cmd_valid = true;
            top.s_cmd_op = static_cast<uint8_t>(c.op);
            top.s_cmd_id = static_cast<uint8_t>(c.id);
            top.s_cmd_x = static_cast<uint32_t>(c.x);
            top.s_cmd_y = static_cast<uint32_t>(c.y);
            top.s_cmd_w = static_cast<uint32_t>(c.w);
            top.s_cmd_h = static_cast<uint32_t>(c.h);
        } else if (blank > 0) {
            --blank;
        } else if (f < n_frames) {
            if (!frame_loaded) {
                if (std::fread(pix.data(), 4, pix.size(), pix_f) != pix.size()) {
                    status = "bad_pixels";
                    detail = "pixel file too short at frame " + std::to_string(f);
                    break;
                }
                frame_loaded = true;
            }
            s_valid = true;
            top.s_axis_tdata = pix[static_cast<std::size_t>(y * W + x)] & 0xFFFFFFu;
            top.s_axis_tuser = at_frame_start;
            top.s_axis_tlast = (x == row_w() - 1);
        }
        top.s_cmd_tvalid = cmd_valid;
        top.s_axis_tvalid = s_valid;
        top.m_axis_result_tready = !(out_pause && pct(rng) < out_pause);
        top.clk = 0;
        top.eval();
        const bool cmd_fire = cmd_valid && top.s_cmd_tready;
        const bool s_fire = s_valid && top.s_axis_tready;
        if (top.m_axis_result_tvalid && top.m_axis_result_tready) {
            std::fprintf(o, "W %lld %s %d %lld\n", n_got, harness::hex_of(top.m_axis_result_tdata).c_str(),
                         static_cast<int>(top.m_axis_result_tlast), cycle);
            ++n_got;
            last_event = cycle;
        }
        if (top.cmd_done) {
            std::fprintf(o, "K %d %d %lld\n", static_cast<int>(top.cmd_code), static_cast<int>(top.cmd_id), cycle);
        }
        top.clk = 1;
        top.eval();
        if (cmd_fire) {
            std::fprintf(o, "T %lld %zu %lld\n", f, next_cmd, cycle);
            ++next_cmd;
            cmd_wait = cmd_gap;
            last_event = cycle;
        }
        if (s_valid && f < n_frames) {
            FrameTimes& ft = times[static_cast<std::size_t>(f)];
            if (!s_fire) ++ft.stalls;
            if (s_fire && at_frame_start) ft.first = cycle;
            if (s_fire) ft.last = cycle;
        }
        if (s_fire) {
            last_event = cycle;
            ++frame_beats;
            if (fault_of(f) == "cut" && frame_beats == 700) {
                x = 0;
                y = 0;
                ++f;
                frame_loaded = false;
                frame_beats = 0;
                blank += vblank;
            } else if (x == row_w() - 1) {
                blank = hblank;
                x = 0;
                if (++y == H) {
                    blank += vblank;
                    y = 0;
                    ++f;
                    frame_loaded = false;
                    frame_beats = 0;
                }
            } else {
                ++x;
            }
        }
        if (cycle - last_event > watchdog) {
            status = "watchdog";
            detail = "nothing happened for " + std::to_string(watchdog) + " clocks (frame " + std::to_string(f) +
                     ", words " + std::to_string(n_got) + ", commands taken " + std::to_string(next_cmd) + ")";
            ++cycle;
            break;
        }
        if (done_at < 0 && f >= n_frames && next_cmd >= cmds.size() && n_got >= n_words) done_at = cycle;
        if (done_at >= 0 && cycle - done_at >= tail) {
            ++cycle;
            break;
        }
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu_secs = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    for (std::size_t i = 0; i < times.size(); ++i) {
        if (times[i].first >= 0)
            std::fprintf(o, "F %zu %lld %lld %lld\n", i, times[i].first, times[i].last, times[i].stalls);
    }
    std::fprintf(o, "E %s %lld %.6f %.6f %s\n", status.c_str(), cycle, secs, cpu_secs, detail.c_str());
    std::fclose(o);
    std::fclose(pix_f);
    top.final();
    std::printf("cycles %lld seconds %.6f status %s\n", cycle, secs, status.c_str());
    return status == "done" ? 0 : 3;
}
