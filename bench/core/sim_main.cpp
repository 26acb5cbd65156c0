// sim_main.cpp -- standalone Verilator harness of bench/core/fmt_core_sim_top.v
// (EXT_CHANNEL = 1): the full-chain RTL simulation of `make sim` without cocotb.
//
// It replays exactly what the cocotb test run_scene (bench/core/core_cocotb.py)
// does, cycle for cycle, with the clock toggled here (two evals per clk cycle, no
// tracing, single thread):
//   phase 1: rst for 8 cycles, one idle cycle, the calibration writes (one per cycle)
//            through the local bus (play_i = 0);
//   (pre_cycles > 0, the reset test of scripts/random_scenes.py --reset: the pre_regs
//            written, then pre_cycles cycles with random ADC words on every column and
//            the event consumer stalling at random (xorshift64 from pre_seed), then one
//            cycle of rst: the reset under test lands on a busy core in the middle of a
//            frame; phase 2 follows as usual)
//   phase 2: play_i = 1, one cycle later rst for reset_cycles cycles, one idle cycle
//            (cycle 0), the register writes (one per cycle), then the clock runs until
//            run_cycles cycles have passed since the first register write;
//   then:    ev_ready_i = 0, 4 cycles, the status registers read over the bus
//            (two cycles each), flush_i pulsed, result JSON written.
//
// The channel (bench/core/fmt_channel_sim.v, bit-exact, in C++): at every clk edge
// with rst low and ce_o high (sample k = k-th such edge since reset)
//   acc[c] = sum_r dac[k - delay][r] * G[r][c] + noise(k, c) + dc + sum_i osc_i(k)
//            + (charger(k) * W[c]) >> 12
//   adc[c] = clip((acc[c] + 2^15) >> 16, -2048, 2047) & ~enob_mask  (>>: floor)
// registered (the core sees it from the next edge on), rst clears it (and the delay
// line: dac[j] = 0 for j < 0).  The additive terms (2^-16 LSB) are those of
// sim/fmt/channel.py FixedEffects: noise(k, c) = (GAUSS[z >> 48] * sigma_q) >> 4 with
// z = splitmix64 mix of key + (((k << 8) | c) + 1) * 0x9E3779B97F4A7C15 (a counter-based
// generator: nothing repeats); oscillator i = (amp_i * SINE[ph_i(k) >> 52]) >> 7 (64-bit
// phase with a sweep term, a burst gate, or a square wave; charger oscillators summed
// into charger(k); channel_fx.h).  Parameters from chan_file (64-bit hex words: key,
// sigma_q, dc_q, enob_mask, delay, n_osc, then 8 words per oscillator), the tables from
// gauss_file (2^16 words) and sine_file (2^12 words), all written by run_sim_rtl.py.  G is 0 until
// phase 2; the coupling updates come from the same record file as the Verilog player's
// (upd.hex: kind 1 = pending write, kind 3 = pending charger weight W[c] write, kind 2 =
// commit stamped with a sample, 0 = end): a commit arms a copy G, W := pending at the first ce edge whose sample index is >= the
// stamp.  The first commit (the initial matrix) is armed by the first edge after the
// phase-2 reset, as the player does; the later ones are armed right after the previous
// copy (no load time here), and a copy at a sample later than its stamp counts as late.
//
// Job "ext_channel 0" (a build with EXT_CHANNEL = 0): the Verilog channel and player of
// the top run instead (cross-check and speed comparison); the harness only clocks.
//
// Serve mode (job "serve_port P", P >= 0; 0 = any free port): after the status reads the
// harness listens on 127.0.0.1:P (non-blocking), prints the line
//   serving the RTL UART on socket://127.0.0.1:<port>
// on stdout (flushed) and keeps clocking the core (ev_ready_i = 1 again, the last
// coupling matrix held, the noise generator running on, the loggers running) while it
// bridges one TCP client at a time to the core's UART: received bytes are sent
// bit-serial (8N1, back to back, serve_div clk per bit = the top's UART_DIV) into
// uart_rx_i; uart_tx_o is sampled every clk (mid-bit) and the decoded bytes are sent to
// the client.  The socket is polled every SERVE_POLL clk only (the clock rate stays).
// Serving ends on SIGINT/SIGTERM, after serve_cycles clk or serve_seconds of wall time
// (0 = no limit), or, with serve_once 1, when the first client disconnects; then the
// logs are flushed and the result is written as without serving (plus a "serve" record
// and serve_start_cycle: the scene's part of the logs ends there).  serve_log (optional)
// gets one line per byte: "H <cycle> <byte>" a host byte whose stop bit has been driven,
// "D <cycle> <byte>" a core byte decoded (at its stop bit), "C <cycle>" / "X <cycle>"
// client connected / gone; <cycle> = cycle_o, the loggers' time base (counted on here
// when the loggers stop).  serve_log_clk >= 0: the loggers (play_i) stop after that many
// clk of serving (the logs of a long session at full size would grow by MB/s); -1: on.
//
// Usage: Vfmt_core_sim_top <job.txt>   (written by bench/core/run_sim_rtl.py, write_cpp_job)
// Progress on stderr when the job says so; result JSON to the job's out path.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <deque>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "Vfmt_core_sim_top.h"
#include "channel_fx.h"
#include "verilated.h"

namespace {

// Word view of a Verilator port of any width (IData / QData / VlWide), little endian.
inline const uint32_t* words_of(const uint32_t& v) { return &v; }
inline const uint32_t* words_of(const uint64_t& v) { return reinterpret_cast<const uint32_t*>(&v); }
template <std::size_t N> inline const uint32_t* words_of(const VlWide<N>& v) { return v.data(); }
inline uint32_t* words_of(uint32_t& v) { return &v; }
inline uint32_t* words_of(uint64_t& v) { return reinterpret_cast<uint32_t*>(&v); }
template <std::size_t N> inline uint32_t* words_of(VlWide<N>& v) { return v.data(); }

// Signed field [lsb +: w] (w <= 32) of a little-endian word array.
inline int32_t get_field(const uint32_t* w, int lsb, int width) {
    const int i = lsb >> 5, s = lsb & 31;
    uint64_t v = w[i];
    if (s + width > 32) v |= static_cast<uint64_t>(w[i + 1]) << 32;
    v = (v >> s) & ((1ull << width) - 1);
    const uint64_t sign = 1ull << (width - 1);
    return static_cast<int32_t>(static_cast<int64_t>(v ^ sign) - static_cast<int64_t>(sign));
}

struct Update {
    uint32_t stamp;
    std::vector<int32_t> g;   // column-major [c * rows + r]
    std::vector<int32_t> w;   // charger weight per column
};

struct Job {
    int rows = 0, cols = 0, cps = 3, frames = 0, progress = 0, ext_channel = 1;
    std::string chan_file, gauss_file, sine_file, upd_file, out;
    std::vector<std::pair<uint32_t, uint32_t>> cal, regs, pre_regs;
    long long pre_cycles = 0;                 // busy cycles before the phase-2 reset
    unsigned long long pre_seed = 1;
    std::vector<std::pair<std::string, uint32_t>> status;
    long long reset_cycles = 16, run_cycles = 0;
    // serve mode (serve_port < 0: off)
    int serve_port = -1, serve_div = 4, serve_once = 0;
    double serve_seconds = 0.0;
    long long serve_cycles = 0, serve_log_clk = -1;
    std::string serve_log;
};

double cpu_seconds() {   // user + system CPU time of this process
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

[[noreturn]] void die(const std::string& msg) {
    std::fprintf(stderr, "sim_main: %s\n", msg.c_str());
    std::exit(2);
}

Job read_job(const char* path) {
    FILE* f = std::fopen(path, "r");
    if (!f) die(std::string("cannot open job ") + path);
    Job j;
    char key[64], sval[4096];
    auto pairs = [&](std::vector<std::pair<uint32_t, uint32_t>>& v) {
        long n;
        if (std::fscanf(f, "%ld", &n) != 1) die("bad count");
        for (long i = 0; i < n; ++i) {
            unsigned a, d;
            if (std::fscanf(f, "%u %u", &a, &d) != 2) die("bad pair");
            v.emplace_back(a, d);
        }
    };
    while (std::fscanf(f, "%63s", key) == 1) {
        const std::string k(key);
        if (k == "rows") { if (std::fscanf(f, "%d", &j.rows) != 1) die(k); }
        else if (k == "cols") { if (std::fscanf(f, "%d", &j.cols) != 1) die(k); }
        else if (k == "cps") { if (std::fscanf(f, "%d", &j.cps) != 1) die(k); }
        else if (k == "frames") { if (std::fscanf(f, "%d", &j.frames) != 1) die(k); }
        else if (k == "progress") { if (std::fscanf(f, "%d", &j.progress) != 1) die(k); }
        else if (k == "ext_channel") { if (std::fscanf(f, "%d", &j.ext_channel) != 1) die(k); }
        else if (k == "reset_cycles") { if (std::fscanf(f, "%lld", &j.reset_cycles) != 1) die(k); }
        else if (k == "run_cycles") { if (std::fscanf(f, "%lld", &j.run_cycles) != 1) die(k); }
        else if (k == "serve_port") { if (std::fscanf(f, "%d", &j.serve_port) != 1) die(k); }
        else if (k == "serve_div") { if (std::fscanf(f, "%d", &j.serve_div) != 1 || j.serve_div < 2) die(k); }
        else if (k == "serve_once") { if (std::fscanf(f, "%d", &j.serve_once) != 1) die(k); }
        else if (k == "serve_seconds") { if (std::fscanf(f, "%lf", &j.serve_seconds) != 1) die(k); }
        else if (k == "serve_cycles") { if (std::fscanf(f, "%lld", &j.serve_cycles) != 1) die(k); }
        else if (k == "serve_log_clk") { if (std::fscanf(f, "%lld", &j.serve_log_clk) != 1) die(k); }
        else if (k == "serve_log") { if (std::fscanf(f, "%4095s", sval) != 1) die(k); j.serve_log = sval; }
        else if (k == "chan_file") { if (std::fscanf(f, "%4095s", sval) != 1) die(k); j.chan_file = sval; }
        else if (k == "gauss_file") { if (std::fscanf(f, "%4095s", sval) != 1) die(k); j.gauss_file = sval; }
        else if (k == "sine_file") { if (std::fscanf(f, "%4095s", sval) != 1) die(k); j.sine_file = sval; }
        else if (k == "upd_file") { if (std::fscanf(f, "%4095s", sval) != 1) die(k); j.upd_file = sval; }
        else if (k == "out") { if (std::fscanf(f, "%4095s", sval) != 1) die(k); j.out = sval; }
        else if (k == "cal") pairs(j.cal);
        else if (k == "regs") pairs(j.regs);
        else if (k == "pre_regs") pairs(j.pre_regs);
        else if (k == "pre_cycles") { if (std::fscanf(f, "%lld", &j.pre_cycles) != 1 || j.pre_cycles < 0) die(k); }
        else if (k == "pre_seed") { if (std::fscanf(f, "%llu", &j.pre_seed) != 1 || j.pre_seed == 0) die(k); }
        else if (k == "status") {
            long n;
            if (std::fscanf(f, "%ld", &n) != 1) die(k);
            for (long i = 0; i < n; ++i) {
                unsigned a;
                if (std::fscanf(f, "%4095s %u", sval, &a) != 2) die(k);
                j.status.emplace_back(sval, a);
            }
        } else die("unknown job key " + k);
    }
    std::fclose(f);
    if (j.rows <= 0 || j.cols <= 0 || j.out.empty()) die("job lacks rows/cols/out");
    return j;
}

// The channel of fmt_channel_sim.v plus the coupling-update sequencing.
struct Channel {
    int rows, cols;
    std::vector<int32_t> g, pending;          // column-major
    std::vector<int32_t> w, pending_w;        // charger weights per column (12 fraction bits)
    Effects fx;
    std::vector<int32_t> dline;               // [(k mod DELAY_MAX) * rows + r]
    std::vector<Update> updates;              // commits in record order
    std::vector<int32_t> dac;
    std::vector<uint32_t> adc_words;          // registered output, packed
    size_t next_upd = 0;                      // next commit to arm
    bool armed = false, arm_next = false, playing = false;
    uint32_t stamp = 0, k = 0;
    long long late = 0, copies = 0, clip_samples = 0;
    bool clip_sticky = false;

    Channel(const Job& j, size_t adc_nwords)
        : rows(j.rows), cols(j.cols),
          g(static_cast<size_t>(rows) * cols, 0), pending(g.size(), 0), w(cols, 0), pending_w(cols, 0),
          dline(static_cast<size_t>(Effects::DELAY_MAX) * rows, 0), dac(rows, 0), adc_words(adc_nwords, 0) {
        if (!j.chan_file.empty()) load_effects(j);
        if (!j.upd_file.empty()) load_updates(j.upd_file);
    }

    // Hex words of a $readmemh file, one per line (no comments or @ addresses: the
    // files are written by sim/fmt); a plain parser (scanf is slow on 5 M words).
    static std::vector<uint64_t> read_hex(const std::string& path) {
        FILE* f = std::fopen(path.c_str(), "rb");
        if (!f) die("cannot open " + path);
        std::fclose(f);
        return Effects::read_hex(path);         // the one hex parser (channel_fx.h)
    }

    void load_effects(const Job& j) {
        const std::string err = fx.load(j.chan_file, j.gauss_file, j.sine_file);
        if (!err.empty()) die(err);
    }

    void load_updates(const std::string& path) {
        std::vector<int32_t> pend(g.size(), 0), pend_w(cols, 0);
        for (const uint64_t rec : read_hex(path)) {
            const unsigned kind = static_cast<unsigned>(rec >> 60);
            if (kind == 0) break;
            if (kind == 1) {
                const int r = static_cast<int>((rec >> 52) & 0xFF), c = static_cast<int>((rec >> 44) & 0xFF);
                if (r < rows && c < cols) pend[static_cast<size_t>(c) * rows + r] = static_cast<int32_t>(rec & 0xFFFF);
            } else if (kind == 3) {
                const int c = static_cast<int>((rec >> 44) & 0xFF);
                if (c < cols) pend_w[static_cast<size_t>(c)] = static_cast<int32_t>(rec & 0xFFFF);
            } else if (kind == 2) {
                updates.push_back(Update{static_cast<uint32_t>(rec & 0xFFFFFFFFu), pend, pend_w});
            }
        }
    }

    // Values at a clk edge (before it): rst, ce, the DAC words; updates the registered
    // output that the core sees from the next edge on.
    template <typename DacT>
    void edge(bool rst, bool ce, const DacT& dac_port) {
        if (rst) {
            k = 0;
            armed = false;
            std::fill(dline.begin(), dline.end(), 0);
            clip_sticky = false;
            std::fill(adc_words.begin(), adc_words.end(), 0u);
            if (playing && next_upd == 0) arm_next = true;   // the initial matrix: first edge after reset
            return;
        }
        bool arm_now = false;
        if (ce) {
            if (armed && k >= stamp) {
                g = pending;
                w = pending_w;
                ++copies;
                if (k > stamp && stamp != 0) ++late;   // as the player: stamp 0 = at once
                armed = false;
                if (next_upd < updates.size()) arm_now = true;   // next commit, armed from the next edge
            }
            const uint32_t* dw = words_of(dac_port);
            if (fx.delay == 0) {
                for (int r = 0; r < rows; ++r) dac[r] = get_field(dw, r * 12, 12);
            } else {                        // ring of DELAY_MAX samples, 0 after reset
                int32_t* slot = &dline[static_cast<size_t>(k % Effects::DELAY_MAX) * rows];
                const int32_t* old = &dline[static_cast<size_t>((k - fx.delay) % Effects::DELAY_MAX) * rows];
                for (int r = 0; r < rows; ++r) dac[r] = old[r];   // sample k - delay (0 before)
                for (int r = 0; r < rows; ++r) slot[r] = get_field(dw, r * 12, 12);
            }
            const int64_t common = fx.common(k);
            const int64_t chg = fx.charger(k);
            std::fill(adc_words.begin(), adc_words.end(), 0u);
            bool clip = false;
            for (int c = 0; c < cols; ++c) {
                const int32_t* gc = &g[static_cast<size_t>(c) * rows];
                int64_t acc = 0;
                for (int r = 0; r < rows; ++r) acc += static_cast<int64_t>(dac[r]) * gc[r];
                acc += fx.noise(k, c) + common;
                if (chg != 0) acc += (chg * w[static_cast<size_t>(c)]) >> 12;
                int64_t y = (acc + (1 << 15)) >> 16;
                if (y > 2047) { y = 2047; clip = true; }
                if (y < -2048) { y = -2048; clip = true; }
                y &= ~fx.enob_mask;
                const uint64_t u = static_cast<uint64_t>(y) & 0xFFF;
                const int lsb = c * 12, i = lsb >> 5, s = lsb & 31;
                adc_words[i] |= static_cast<uint32_t>(u << s);
                if (s + 12 > 32) adc_words[i + 1] |= static_cast<uint32_t>(u >> (32 - s));
            }
            if (clip) { clip_sticky = true; ++clip_samples; }
            ++k;
        }
        if (arm_next || arm_now) {          // registered: takes effect from the next edge
            if (next_upd < updates.size()) {
                pending = updates[next_upd].g;
                pending_w = updates[next_upd].w;
                stamp = updates[next_upd].stamp;
                ++next_upd;
                armed = true;
            }
            arm_next = false;
        }
    }
};

// Host -> core: 8N1 bit-serial, bytes back to back, div clk per bit.
struct UartTx {
    int div;
    std::deque<uint8_t> q;
    uint32_t frame = 0;     // bits still to send, LSB first (start, data, stop)
    int nbits = 0, cnt = 0;
    bool done = false;      // the clk just driven was the last of a stop bit
    uint8_t byte = 0;       // the byte being (or just) sent
    explicit UartTx(int d) : div(d) {}
    int next_level() {      // pin level for the coming clk cycle
        done = false;
        if (cnt == 0) {
            if (nbits == 0) {
                if (q.empty()) return 1;
                byte = q.front();
                q.pop_front();
                frame = (1u << 9) | (static_cast<uint32_t>(byte) << 1);
                nbits = 10;
            }
            cnt = div;
        }
        const int lvl = static_cast<int>(frame & 1u);
        if (--cnt == 0) {
            frame >>= 1;
            if (--nbits == 0) done = true;
        }
        return lvl;
    }
};

// Core -> host: the pin sampled once per clk; a byte is taken at the middle of its
// stop bit (start bit checked at its middle too; a low stop bit counts as framing error).
struct UartRx {
    int div, state = 0, wait = 0, bit = 0;
    uint32_t sh = 0;
    long long framing_errors = 0;
    explicit UartRx(int d) : div(d) {}
    int sample(int lvl) {   // returns the byte completed at this clk or -1
        if (state == 0) {
            if (!lvl) { state = 1; wait = div / 2; bit = 0; sh = 0; }
            return -1;
        }
        if (--wait > 0) return -1;
        wait = div;
        if (bit == 0) {
            if (lvl) state = 0;              // glitch, not a start bit
            bit = 1;
            return -1;
        }
        if (bit <= 8) {
            sh |= static_cast<uint32_t>(lvl & 1) << (bit - 1);
            ++bit;
            return -1;
        }
        state = 0;
        if (!lvl) { ++framing_errors; return -1; }
        return static_cast<int>(sh & 0xFF);
    }
};

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int) { g_stop = 1; }

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) die("usage: Vfmt_core_sim_top <job.txt>");
    const Job job = read_job(argv[1]);
    auto ctx = std::make_unique<VerilatedContext>();
    ctx->commandArgs(1, argv);
    auto top = std::make_unique<Vfmt_core_sim_top>(ctx.get(), "TOP");
    constexpr size_t ADC_NWORDS = (sizeof(top->adc_ext_i) + 3) / 4;
    if (static_cast<size_t>(job.cols) * 12 > ADC_NWORDS * 32 ||
        static_cast<size_t>(job.rows) * 12 > sizeof(top->dac_o) * 8)
        die("job size does not match the build");
    Job chjob = job;
    if (!job.ext_channel) { chjob.chan_file.clear(); chjob.upd_file.clear(); }
    Channel ch(chjob, ADC_NWORDS);
    const bool cpp_channel = job.ext_channel != 0;   // 0: the Verilog channel of the top runs

    long long cycle = 0;   // clk edges since time 0 (all phases)
    auto tick = [&]() {
        if (cpp_channel) ch.edge(top->rst != 0, top->ce_o != 0, top->dac_o);
        top->clk = 1;
        top->eval();
        if (cpp_channel) std::memcpy(words_of(top->adc_ext_i), ch.adc_words.data(), ADC_NWORDS * 4);
        top->clk = 0;
        top->eval();
        ++cycle;
    };
    auto ticks = [&](long long n) { for (long long i = 0; i < n; ++i) tick(); };
    auto bus_write = [&](uint32_t addr, uint32_t data) {
        top->bus_we_i = 1;
        top->bus_addr_i = addr & 0xFFFF;
        top->bus_wdata_i = data;
        tick();
        top->bus_we_i = 0;
    };
    auto bus_read = [&](uint32_t addr) -> uint32_t {
        top->bus_re_i = 1;
        top->bus_addr_i = addr & 0xFFFF;
        tick();
        top->bus_re_i = 0;
        tick();
        return top->bus_rdata_o;
    };

    top->clk = 0; top->rst = 0; top->ev_ready_i = 1; top->trig_i = 0; top->uart_rx_i = 1;
    top->bus_we_i = 0; top->bus_re_i = 0; top->bus_addr_i = 0; top->bus_wdata_i = 0;
    top->flush_i = 0; top->play_i = 0;
    top->eval();

    // phase 1: calibration (kept through the next reset)
    top->rst = 1; ticks(8); top->rst = 0;
    tick();
    for (const auto& w : job.cal) bus_write(w.first, w.second);
    // the busy core before the reset under test (cpp channel only: its ADC words are
    // replaced; the channel itself restarts at the reset)
    if (job.pre_cycles > 0) {
        if (!cpp_channel) die("pre_cycles needs the C++ channel (ext_channel 1)");
        for (const auto& w : job.pre_regs) bus_write(w.first, w.second);
        unsigned long long x = job.pre_seed;
        auto rnd = [&x]() { x ^= x << 13; x ^= x >> 7; x ^= x << 17; return x; };
        const size_t nbits = static_cast<size_t>(job.cols) * 12;
        for (long long i = 0; i < job.pre_cycles; ++i) {
            top->ev_ready_i = (rnd() & 3) != 0;
            tick();
            uint32_t* aw = words_of(top->adc_ext_i);
            for (size_t w = 0; w < ADC_NWORDS; ++w) {
                const size_t lo = w * 32;
                const uint32_t m = nbits >= lo + 32 ? 0xFFFFFFFFu
                                 : (nbits > lo ? ((1u << (nbits - lo)) - 1u) : 0u);
                aw[w] = static_cast<uint32_t>(rnd()) & m;
            }
        }
        // the reset under test: one cycle, here, so that nothing of the busy core
        // leaves in the one cycle of phase 2 before its reset (the loggers run from
        // play_i = 1 on); phase 2's own reset then meets an idle core
        top->rst = 1; tick(); top->rst = 0;
        top->ev_ready_i = 1;
    }
    // phase 2: the run
    top->play_i = 1; ch.playing = true;
    tick();
    top->rst = 1; ticks(job.reset_cycles); top->rst = 0;
    tick();                                                  // cycle 0
    for (const auto& w : job.regs) bus_write(w.first, w.second);
    long long done = static_cast<long long>(job.regs.size());
    const long long total = job.run_cycles;
    const long long step = std::max<long long>(1000, total / 100);
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    int line_step = 0;                                       // progress 2: last 10 % step printed
    double line_t = 0.0;                                     // progress 2: time of the last line
    while (done < total) {
        const long long n = std::min(step, total - done);
        ticks(n);
        done += n;
        if (job.progress) {
            // progress 1: a terminal, the line is rewritten in place; progress 2: a log, whole
            // lines, one per 10 % or 10 s (and the last)
            const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const int pct = static_cast<int>(100.0 * done / total);
            if (job.progress == 1 || pct / 10 > line_step || dt - line_t >= 10.0 || done >= total) {
                const unsigned fr = top->frames_o;
                std::fprintf(stderr, job.progress == 1
                                 ? "\r  fmt_core (Verilator, C++ harness): frame %u/%d  %3d%%  %.0f frames/s, %.0f clk/s   "
                                 : "  fmt_core (Verilator, C++ harness): frame %u/%d  %3d%%  %.0f frames/s, %.0f clk/s\n",
                             fr, job.frames, pct, fr / std::max(dt, 1e-9),
                             (done - static_cast<long long>(job.regs.size())) / std::max(dt, 1e-9));
                std::fflush(stderr);
                line_step = pct / 10;
                line_t = dt;
            }
        }
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = cpu_seconds() - c0;
    if (job.progress == 1) std::fprintf(stderr, "\n");
    const unsigned frames = top->frames_o, events = top->events_o;
    const long long run_clk = total - static_cast<long long>(job.regs.size());
    // stop the event consumer so that the counters hold still while they are read
    top->ev_ready_i = 0;
    ticks(4);
    const unsigned status_cycle = top->cycle_o, frames_before = top->frames_o;
    std::string st;
    for (const auto& s : job.status) {
        const uint32_t v = bus_read(s.second);
        st += (st.empty() ? "" : ", ") + ("\"" + s.first + "\": " + std::to_string(v));
    }
    const unsigned frames_at = top->frames_o;

    // ---- serve mode: the core's UART on a TCP port (see the header) ----
    std::string serve_json;
    if (job.serve_port >= 0) {
        constexpr long long SERVE_POLL = 256;      // clk between socket polls
        const unsigned serve_start = top->cycle_o;
        top->ev_ready_i = 1;
        const int lfd = socket(AF_INET, SOCK_STREAM, 0);
        if (lfd < 0) die(std::string("socket: ") + std::strerror(errno));
        const int one = 1;
        setsockopt(lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        sockaddr_in sa{};
        sa.sin_family = AF_INET;
        sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        sa.sin_port = htons(static_cast<uint16_t>(job.serve_port));
        if (bind(lfd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0)
            die("cannot listen on 127.0.0.1:" + std::to_string(job.serve_port) + ": " + std::strerror(errno));
        if (listen(lfd, 4) != 0) die(std::string("listen: ") + std::strerror(errno));
        fcntl(lfd, F_SETFL, fcntl(lfd, F_GETFL) | O_NONBLOCK);
        socklen_t sl = sizeof sa;
        getsockname(lfd, reinterpret_cast<sockaddr*>(&sa), &sl);
        const int port = ntohs(sa.sin_port);
        std::signal(SIGINT, on_stop_signal);
        std::signal(SIGTERM, on_stop_signal);
        FILE* slog = job.serve_log.empty() ? nullptr : std::fopen(job.serve_log.c_str(), "w");
        if (!job.serve_log.empty() && !slog) die("cannot write " + job.serve_log);
        std::printf("serving the RTL UART on socket://127.0.0.1:%d\n", port);
        std::fflush(stdout);
        UartTx utx(job.serve_div);
        UartRx urx(job.serve_div);
        std::vector<uint8_t> out;
        int cfd = -1;
        long long clients = 0, bytes_in = 0, bytes_out = 0, serve_clk = 0;
        unsigned cyc = serve_start;                // = cycle_o while the loggers run
        const char* why = "signal";
        const auto s0 = std::chrono::steady_clock::now();
        for (;;) {
            for (long long i = 0; i < SERVE_POLL; ++i) {
                top->uart_rx_i = utx.next_level();
                tick();
                ++cyc;
                if (utx.done && slog) std::fprintf(slog, "H %u %u\n", cyc, utx.byte);
                const int b = urx.sample(top->uart_tx_o);
                if (b >= 0) {
                    if (slog) std::fprintf(slog, "D %u %d\n", cyc, b);
                    if (cfd >= 0) out.push_back(static_cast<uint8_t>(b));
                }
            }
            serve_clk += SERVE_POLL;
            if (job.serve_log_clk >= 0 && serve_clk >= job.serve_log_clk) top->play_i = 0;   // loggers off
            if (cfd < 0) {
                cfd = accept(lfd, nullptr, nullptr);
                if (cfd >= 0) {
                    fcntl(cfd, F_SETFL, fcntl(cfd, F_GETFL) | O_NONBLOCK);
                    ++clients;
                    if (slog) std::fprintf(slog, "C %u\n", cyc);
                }
            }
            bool gone = false;
            if (cfd >= 0) {
                uint8_t buf[4096];
                for (;;) {
                    const ssize_t n = recv(cfd, buf, sizeof buf, 0);
                    if (n > 0) { utx.q.insert(utx.q.end(), buf, buf + n); bytes_in += n; continue; }
                    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) gone = true;
                    break;
                }
                while (!gone && !out.empty()) {
                    const ssize_t n = send(cfd, out.data(), out.size(), MSG_NOSIGNAL);
                    if (n > 0) { out.erase(out.begin(), out.begin() + n); bytes_out += n; continue; }
                    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) break;
                    gone = true;
                }
                if (gone) {
                    close(cfd);
                    cfd = -1;
                    out.clear();
                    if (slog) std::fprintf(slog, "X %u\n", cyc);
                }
            }
            if (g_stop) { why = "signal"; break; }
            if (gone && job.serve_once) { why = "client"; break; }
            if (job.serve_cycles > 0 && serve_clk >= job.serve_cycles) { why = "cycles"; break; }
            if (job.serve_seconds > 0.0 &&
                std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count() >= job.serve_seconds) {
                why = "seconds";
                break;
            }
        }
        if (cfd >= 0) close(cfd);
        close(lfd);
        if (slog) std::fclose(slog);
        const double sw = std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
        if (job.progress)
            std::fprintf(stderr, "served %lld clk in %.1f s (%lld clients, %lld bytes in, %lld out), end: %s\n",
                         serve_clk, sw, clients, bytes_in, bytes_out, why);
        char tmp[512];
        std::snprintf(tmp, sizeof tmp,
                      ", \"serve_start_cycle\": %u, \"serve\": {\"port\": %d, \"clk\": %lld, \"wall_s\": %.3f, "
                      "\"clients\": %lld, \"bytes_in\": %lld, \"bytes_out\": %lld, \"framing_errors\": %lld, "
                      "\"end\": \"%s\", \"end_cycle\": %u}",
                      serve_start, port, serve_clk, sw, clients, bytes_in, bytes_out, urx.framing_errors, why,
                      cyc);
        serve_json = tmp;
    }
    top->flush_i = 1; tick(); top->flush_i = 0; ticks(2);
    top->final();

    FILE* o = std::fopen(job.out.c_str(), "w");
    if (!o) die("cannot write " + job.out);
    std::fprintf(o,
                 "{\"engine\": \"cpp\", \"wall_s\": %.6f, \"cpu_s\": %.6f, \"run_clk\": %lld, \"clk_per_s\": %.1f, "
                 "\"frames\": %u, \"events\": %u, \"upd_late\": %lld, \"upd_done\": %d, \"upd_copies\": %lld, "
                 "\"clip\": %d, \"clip_samples\": %lld, \"status_cycle\": %u, \"frames_before_status\": %u, "
                 "\"status\": {%s}, \"frames_at_status\": %u%s}\n",
                 wall, cpu, run_clk, run_clk / std::max(wall, 1e-9), frames, events,
                 cpp_channel ? ch.late : static_cast<long long>(top->upd_late_o),
                 cpp_channel ? ((ch.next_upd == ch.updates.size() && !ch.armed) ? 1 : 0) : static_cast<int>(top->upd_done_o),
                 cpp_channel ? ch.copies : -1LL,
                 cpp_channel ? (ch.clip_sticky ? 1 : 0) : static_cast<int>(top->clip_o), ch.clip_samples, status_cycle, frames_before, st.c_str(), frames_at,
                 serve_json.c_str());
    std::fclose(o);
    return 0;
}
