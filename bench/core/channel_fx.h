// channel_fx.h -- the additive effects of the `make sim` channel in C++ (counter-based
// Gaussian noise, DC offset, oscillators: interferers that may sweep and burst, display
// and charger harmonics; the delay length and ENOB mask are carried here too), bit-exact with sim/fmt/channel.py FixedEffects (numpy) and
// bench/core/fmt_channel_sim.v fx_noise / fx_osc (Verilog).  Used by sim_main.cpp;
// tb/fmt_core/test_channel_effects.py compiles it alone to compare the words.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

// The additive effects of the channel (sim/fmt/channel.py FixedEffects, bit-exact).
struct Effects {
    static constexpr int DELAY_MAX = 64;      // delay line length (samples)
    uint64_t key = 0;
    int64_t sigma_q = 0, dc_q = 0, enob_mask = 0;
    int delay = 0;
    // one oscillator (interferer, display or charger harmonic): 32-bit phase step and
    // start, amplitude, 64-bit step of the step (sweep), burst gate, flags (1 square, 2 charger)
    struct If { uint32_t inc, ph0; int64_t amp; uint64_t dinc, bper, bon; int64_t bstart; uint64_t flags; };
    std::vector<If> ifs;
    bool has_charger = false;
    std::vector<int64_t> gauss, sine;         // 2^16 and 2^12 signed table words

    static uint64_t mix64(uint64_t z) {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    // Noise word of channel sample k, column c (2^-16 LSB).
    int64_t noise(uint32_t k, int c) const {
        if (sigma_q == 0) return 0;
        const uint64_t ctr = (static_cast<uint64_t>(k) << 8) | static_cast<uint64_t>(c);
        const uint64_t z = mix64(key + (ctr + 1) * 0x9E3779B97F4A7C15ull);
        return (gauss[z >> 48] * sigma_q) >> 4;
    }
    // Sum of the oscillators with (charger) or without the charger flag at channel sample
    // k (2^-16 LSB): 64-bit phase ((ph0 + k inc) mod 2^32) << 32 + dinc k (k - 1) / 2.
    int64_t osc_sum(uint32_t k, bool charger) const {
        int64_t v = 0;
        const uint64_t k64 = k;
        const uint64_t tk = (k64 * (k64 - 1)) >> 1;        // exact: k < 2^32
        for (const If& i : ifs) {
            if (((i.flags & 2) != 0) != charger) continue;
            if (i.bper != 0) {
                const int64_t d = static_cast<int64_t>(k64) - i.bstart;
                if (d < 0 || static_cast<uint64_t>(d) % i.bper >= i.bon) continue;
            }
            const uint64_t ph = (static_cast<uint64_t>(i.ph0 + k * i.inc) << 32) + i.dinc * tk;   // mod 2^64
            const int64_t w = (i.flags & 1) ? ((ph >> 63) ? -32767 : 32767) : sine[ph >> 52];
            v += (i.amp * w) >> 7;
        }
        return v;
    }
    // DC plus the oscillators added to every column at channel sample k (2^-16 LSB).
    int64_t common(uint32_t k) const { return dc_q + osc_sum(k, false); }
    // The charger oscillators at channel sample k; column c adds (charger * W_c) >> 12.
    int64_t charger(uint32_t k) const { return has_charger ? osc_sum(k, true) : 0; }

    // Hex words of a $readmemh file, one per line (files written by sim/fmt; no
    // comments or @ addresses); empty on a missing file.
    static std::vector<uint64_t> read_hex(const std::string& path) {
        std::vector<uint64_t> out;
        FILE* f = std::fopen(path.c_str(), "rb");
        if (!f) return out;
        std::string buf;
        char tmp[1 << 16];
        size_t n;
        while ((n = std::fread(tmp, 1, sizeof tmp, f)) > 0) buf.append(tmp, n);
        std::fclose(f);
        uint64_t v = 0;
        bool in = false;
        for (const char ch : buf) {
            int d = -1;
            if (ch >= '0' && ch <= '9') d = ch - '0';
            else if (ch >= 'a' && ch <= 'f') d = ch - 'a' + 10;
            else if (ch >= 'A' && ch <= 'F') d = ch - 'A' + 10;
            if (d >= 0) { v = (v << 4) | static_cast<uint64_t>(d); in = true; }
            else if (in) { out.push_back(v); v = 0; in = false; }
        }
        if (in) out.push_back(v);
        return out;
    }
    // Load the parameter words (key, sigma_q, dc_q, enob_mask, delay, n_osc, then inc, ph0,
    // amp, dinc, bper, bon, bstart, flags per oscillator) and the two tables; returns "" or what is wrong.
    std::string load(const std::string& chan, const std::string& gauss_file, const std::string& sine_file) {
        const std::vector<uint64_t> w = read_hex(chan);
        if (w.size() < 6) return "chan file " + chan + " missing or short";
        key = w[0];
        sigma_q = static_cast<int64_t>(w[1]);
        dc_q = static_cast<int64_t>(w[2]);
        enob_mask = static_cast<int64_t>(w[3]);
        delay = static_cast<int>(w[4]);
        const size_t n_if = static_cast<size_t>(w[5]);
        if (w[4] > static_cast<uint64_t>(DELAY_MAX) || n_if > 64 || w.size() < 6 + 8 * n_if) return "bad chan file " + chan;
        ifs.clear();
        has_charger = false;
        for (size_t i = 0; i < n_if; ++i) {
            const uint64_t* p = &w[6 + 8 * i];
            ifs.push_back(If{static_cast<uint32_t>(p[0]), static_cast<uint32_t>(p[1]), static_cast<int64_t>(p[2]),
                             p[3], p[4], p[5], static_cast<int64_t>(p[6]), p[7]});
            if (p[7] & 2) has_charger = true;
        }
        const auto table = [](const std::string& path, size_t n, std::vector<int64_t>& t) -> bool {
            const std::vector<uint64_t> v = read_hex(path);
            if (v.size() != n) return false;
            t.resize(n);
            for (size_t i = 0; i < n; ++i) t[i] = static_cast<int16_t>(v[i] & 0xFFFF);
            return true;
        };
        if (!table(gauss_file, 1u << 16, gauss)) return "Gaussian table " + gauss_file + " missing or not 2^16 words";
        if (!table(sine_file, 1u << 12, sine)) return "sine table " + sine_file + " missing or not 2^12 words";
        return "";
    }
};
