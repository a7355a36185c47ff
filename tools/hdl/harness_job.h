// harness_job.h: what the Verilator harnesses of tools/hdl share (cosim_main.cpp, drv_main.cpp,
// multi_main.cpp): the job file and the hex form of a wide port.  Include after "verilated.h".
#ifndef MSTRACK_HARNESS_JOB_H
#define MSTRACK_HARNESS_JOB_H

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace harness {

// A job file: one "key value" per line, '#' starts a comment line.  Keys listed in `repeated` may
// appear on several lines; their values are kept in order in `lines` (key, rest of the line).
struct Job {
    std::map<std::string, std::string> kv;
    std::vector<std::pair<std::string, std::string>> lines;

    long long num(const char* k, long long d) const {
        auto it = kv.find(k);
        return it == kv.end() ? d : std::stoll(it->second, nullptr, 0);
    }
    bool has(const char* k) const { return kv.count(k) != 0; }
    const std::string& str(const char* k) const { return kv.at(k); }
};

// Read *path* into *job*; false (and a message on stderr) when it cannot be read.
inline bool read_job(const char* path, Job& job, const std::vector<std::string>& repeated = {}) {
    std::ifstream f(path);
    if (!f) {
        std::fprintf(stderr, "cannot read %s\n", path);
        return false;
    }
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ls(line);
        std::string k, v;
        if (!(ls >> k)) continue;
        std::getline(ls >> std::ws, v);
        bool rep = false;
        for (const auto& r : repeated) rep = rep || r == k;
        if (rep) {
            job.lines.emplace_back(k, v);
        } else {
            job.kv[k] = v;
        }
    }
    return true;
}

// Hex of a wide port value, MSB first, zero-padded to whole 32-bit words.
template <std::size_t N>
std::string hex_of(const VlWide<N>& w) {
    std::string s;
    char buf[9];
    for (std::size_t i = N; i-- > 0;) {
        std::snprintf(buf, sizeof buf, "%08x", static_cast<unsigned>(w[i]));
        s += buf;
    }
    return s;
}

}  // namespace harness

#endif
