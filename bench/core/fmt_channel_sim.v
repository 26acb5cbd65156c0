// fmt_channel_sim -- SIMULATION-ONLY channel model for full-chain simulations: the
// DDS bank's row words, a ROWS x COLS coupling matrix and additive effects (counter-
// based Gaussian noise, DC offset, interferers), channel delay and ENOB make COLS ADC
// samples per sample strobe.  Not synthesizable by intent (64-bit arithmetic,
// whole-matrix copies, tables from files); it lives in bench/core/, not rtl/.
//
// Sample k = k-th ce edge after reset; the row words present at that edge are sample k.
//   acc[c] = sum_r dac[k - delay][r] * G[r][c] + fnoise[(k mod NOISE_LEN)][c] << (COUP_FRAC - NOISE_FRAC)
//            + noise(k, c) + dc_q + sum_i osc_i(k) + (chg(k) * W[c]) >>> 12
//   y[c]   = (acc[c] + 2^(COUP_FRAC-1)) >>> COUP_FRAC          (round half up)
//   adc[c] = clip(y[c], -2^(ADC_BITS-1), 2^(ADC_BITS-1) - 1) & ~enob_mask,
//   clip_o = any column clipped (before the ENOB mask)
// G[r][c] is unsigned COUP_BITS with COUP_FRAC fractional bits (in ADC LSB per DAC
// LSB).  File noise (tests of this module only): signed NOISE_BITS words with
// NOISE_FRAC fractional bits, NOISE_LEN x COLS, row-major (sample, column), from the
// $readmemh file NOISE_FILE ("" = none).
// Effects (CHAN_FILE, "" = none; the bench's channel, twin sim/fmt/channel.py
// FixedEffects, terms in 2^-16 LSB, so COUP_FRAC must be 16 when CHAN_FILE is used):
// CHAN_FILE = 64-bit words key, sigma_q, dc_q, enob_mask, delay, n_osc, then (inc, ph0,
// amp, dinc, bper, bon, bstart, flags) per oscillator (<= IF_MAX); GAUSS_FILE = 2^16
// signed 16-bit words, SINE_FILE = 2^12 signed 16-bit words.
//   noise(k, c)       = (GAUSS[z[63:48]] * sigma_q) >>> 4,
//                       z = mix64(key + ({k, c[7:0]} + 1) * 64'h9E3779B97F4A7C15)  (splitmix64)
//   osc_i(k)          = gate_i(k) ? (amp_i * word_i) >>> 7 : 0, with the 64-bit phase
//                       ph = {ph0_i + k * inc_i, 32'd0} + dinc_i * (k (k - 1) / 2),
//                       word = SINE[ph[63:52]], or +-32767 by ph[63] (flags[0]: square);
//                       gate = bper_i == 0 || (k >= bstart_i && (k - bstart_i) % bper_i < bon_i)
//   chg(k)            = the sum of the oscillators with flags[1] (charger), which are
//                       not in the common sum; W[c] = unsigned 16-bit charger weight.
//   dac[k - delay]    = the row words of sample k - delay from a DELAY_MAX-sample line,
//                       0 before sample ``delay`` (the line is cleared by reset).
// Output registered: adc_o / clip_o after ce edge k belong to sample k (latency 1).
// clip_sticky_o stays 1 from the first clipped sample until reset.
//
// Coupling updates, stamped with the sample index at which they apply:
//   upd_we_i writes G_pending[upd_row_i][upd_col_i] = upd_data_i (any clk cycle), or
//   with upd_chg_i = 1 the pending charger weight W_pending[upd_col_i] = upd_data_i;
//   upd_commit_i arms a copy G, W := G_pending, W_pending stamped upd_stamp_i; the copy happens at
//   the first ce edge whose sample index is >= the stamp, and that sample already uses
//   the new G (so a touch can start on its exact onset sample).  One armed copy at a
//   time (a new commit replaces an armed one).  Reset clears the sample counter, the
//   armed copy, the outputs and the sticky flag; G, W and the pending copies keep their contents
//   (both are 0 at time 0).  Twin: sim/fmt/channel.py channel_sim_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_channel_sim #(
    parameter ROWS       = `FMT_ROWS,      // transmit rows
    parameter COLS       = `FMT_COLS,      // receive columns
    parameter DAC_BITS   = `FMT_DAC_BITS,  // row word width (signed)
    parameter ADC_BITS   = `FMT_ADC_BITS,  // ADC word width (signed)
    parameter COUP_BITS  = 16,             // coupling width (unsigned)
    parameter COUP_FRAC  = 16,             // coupling fractional bits (<= 40)
    parameter NOISE_BITS = 16,             // noise word width (signed)
    parameter NOISE_FRAC = 4,              // noise fractional bits (<= COUP_FRAC)
    parameter NOISE_LEN  = 1024,           // noise samples per column in the file
    parameter NOISE_FILE = "",             // $readmemh file of noise words ("" = none)
    parameter CHAN_FILE  = "",             // $readmemh file of effect parameters ("" = none)
    parameter GAUSS_FILE = "",             // $readmemh Gaussian table (2^16 words), with CHAN_FILE
    parameter SINE_FILE  = "",             // $readmemh interferer sine table (2^12 words), with CHAN_FILE
    parameter IF_MAX     = 64,             // oscillators at most
    parameter DELAY_MAX  = 64,             // channel delay at most (samples, a power of 2)
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,  // width of upd_row_i
    parameter COL_W      = (COLS > 1) ? $clog2(COLS) : 1   // width of upd_col_i
) (
    input  wire                      clk,
    input  wire                      rst,            // synchronous, active high
    input  wire                      ce,             // sample strobe
    input  wire [ROWS*DAC_BITS-1:0]  dac_i,          // row r at [r*DAC_BITS +: DAC_BITS]
    input  wire                      upd_we_i,       // write one pending coupling
    input  wire                      upd_chg_i,      // ... or (1) one pending charger weight
    input  wire [ROW_W-1:0]          upd_row_i,      // its row
    input  wire [COL_W-1:0]          upd_col_i,      // its column
    input  wire [COUP_BITS-1:0]      upd_data_i,     // its value
    input  wire                      upd_commit_i,   // arm G := G_pending at upd_stamp_i
    input  wire [31:0]               upd_stamp_i,    // sample index of the copy
    output reg  [COLS*ADC_BITS-1:0]  adc_o,          // column c at [c*ADC_BITS +: ADC_BITS]
    output reg                       clip_o,         // this sample clipped (any column)
    output reg                       clip_sticky_o,  // some sample clipped since reset
    output reg  [31:0]               sample_o        // index of the sample on adc_o
);

    reg [COUP_BITS-1:0]  g_q    [0:ROWS*COLS-1];
    reg [COUP_BITS-1:0]  gp_q   [0:ROWS*COLS-1];
    reg [NOISE_BITS-1:0] noise  [0:NOISE_LEN*COLS-1];
    reg [COUP_BITS-1:0]  w_q    [0:COLS-1];
    reg [COUP_BITS-1:0]  wp_q   [0:COLS-1];
    reg [63:0]           par    [0:6+8*IF_MAX-1];
    reg [15:0]           gauss  [0:65535];
    reg [15:0]           sine   [0:4095];
    reg [DAC_BITS-1:0]   dline  [0:DELAY_MAX*ROWS-1];
    reg [31:0]           k_q;
    reg                  armed_q;
    reg [31:0]           stamp_q;

    integer r, c, idx;
    reg signed [63:0] acc, y, nz, common, chg;
    reg               clip_any;
    reg [ROWS*DAC_BITS-1:0] dac_d;

    // effect parameters (0 = off until CHAN_FILE is read)
    wire        [63:0] key      = par[0];
    wire signed [63:0] sigma_q  = par[1];
    wire signed [63:0] dc_q     = par[2];
    wire        [63:0] enob_msk = par[3];
    wire        [31:0] delay    = par[4][31:0];
    wire        [31:0] n_if     = par[5][31:0];

    function [63:0] mix64;                 // splitmix64's finaliser (wrapping 64-bit)
        input [63:0] v;
        reg   [63:0] t;
        begin
            t     = (v ^ (v >> 30)) * 64'hBF58476D1CE4E5B9;
            t     = (t ^ (t >> 27)) * 64'h94D049BB133111EB;
            mix64 = t ^ (t >> 31);
        end
    endfunction

    // zz[47:0] / p[19:0] unused: the tables are indexed by the top bits
    /* verilator lint_off UNUSEDSIGNAL */
    function signed [63:0] fx_noise;       // noise word of sample kk, column cc (2^-16 LSB)
        input [31:0] kk;
        input [7:0]  cc;
        reg   [63:0] zz;
        reg signed [63:0] w;
        begin
            zz = mix64(key + ({24'd0, kk, cc} + 64'd1) * 64'h9E3779B97F4A7C15);
            w  = {{48{gauss[zz[63:48]][15]}}, gauss[zz[63:48]]};
            fx_noise = (sigma_q == 64'sd0) ? 64'sd0 : ((w * sigma_q) >>> 4);
        end
    endfunction

    // sum of the oscillators whose charger flag equals sel at sample kk (2^-16 LSB)
    function signed [63:0] fx_osc;
        input [31:0] kk;
        input        sel;
        integer      j, b;
        reg   [31:0] p;
        reg   [63:0] k64, tk, ph;
        reg signed [63:0] v, wd;
        reg          on;
        begin
            v   = 64'sd0;
            k64 = {32'd0, kk};
            tk  = (k64 * (k64 - 64'd1)) >> 1;
            for (j = 0; j < IF_MAX; j = j + 1)
                if (j < n_if && par[13 + 8 * j][1] == sel) begin
                    b  = 6 + 8 * j;
                    p  = par[b + 1][31:0] + kk * par[b][31:0];
                    ph = {p, 32'd0} + par[b + 3] * tk;
                    if (par[b + 7][0]) wd = ph[63] ? -64'sd32767 : 64'sd32767;
                    else               wd = {{48{sine[ph[63:52]][15]}}, sine[ph[63:52]]};
                    on = 1'b1;
                    if (par[b + 4] != 64'd0)
                        on = ($signed(k64) >= $signed(par[b + 6])) &&
                             (((k64 - par[b + 6]) % par[b + 4]) < par[b + 5]);
                    if (on) v = v + (($signed(par[b + 2]) * wd) >>> 7);
                end
            fx_osc = v;
        end
    endfunction

    function signed [63:0] fx_common;      // DC + the common oscillators at sample kk
        input [31:0] kk;
        fx_common = dc_q + fx_osc(kk, 1'b0);
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */

    localparam signed [63:0] HI = (64'sd1 <<< (ADC_BITS - 1)) - 1;
    localparam signed [63:0] LO = -(64'sd1 <<< (ADC_BITS - 1));
    localparam signed [63:0] HALF = (COUP_FRAC > 0) ? (64'sd1 <<< (COUP_FRAC - 1)) : 64'sd0;

    initial begin
        for (idx = 0; idx < ROWS * COLS; idx = idx + 1) begin
            g_q[idx]  = {COUP_BITS{1'b0}};
            gp_q[idx] = {COUP_BITS{1'b0}};
        end
        for (idx = 0; idx < COLS; idx = idx + 1) begin
            w_q[idx]  = {COUP_BITS{1'b0}};
            wp_q[idx] = {COUP_BITS{1'b0}};
        end
        for (idx = 0; idx < NOISE_LEN * COLS; idx = idx + 1) noise[idx] = {NOISE_BITS{1'b0}};
        if (NOISE_FILE != "") $readmemh(NOISE_FILE, noise);
        for (idx = 0; idx < 6 + 8 * IF_MAX; idx = idx + 1) par[idx] = 64'd0;
        for (idx = 0; idx < 65536; idx = idx + 1) gauss[idx] = 16'd0;
        for (idx = 0; idx < 4096; idx = idx + 1) sine[idx] = 16'd0;
        for (idx = 0; idx < DELAY_MAX * ROWS; idx = idx + 1) dline[idx] = {DAC_BITS{1'b0}};
        if (CHAN_FILE != "") begin
            $readmemh(CHAN_FILE, par);
            $readmemh(GAUSS_FILE, gauss);
            $readmemh(SINE_FILE, sine);
        end
    end

    // Simulation model: blocking temporaries (acc, y, the matrix copy) inside the
    // clocked process are intended; nothing else reads them.
    /* verilator lint_off BLKSEQ */
    always @(posedge clk) begin
        if (upd_we_i && !upd_chg_i && upd_row_i < ROWS && upd_col_i < COLS)
            gp_q[upd_row_i * COLS + upd_col_i] <= upd_data_i;
        if (upd_we_i && upd_chg_i && upd_col_i < COLS)
            wp_q[upd_col_i] <= upd_data_i;
        if (rst) begin
            k_q           <= 32'd0;
            armed_q       <= 1'b0;
            adc_o         <= {(COLS * ADC_BITS){1'b0}};
            clip_o        <= 1'b0;
            clip_sticky_o <= 1'b0;
            sample_o      <= 32'd0;
            for (idx = 0; idx < DELAY_MAX * ROWS; idx = idx + 1) dline[idx] = {DAC_BITS{1'b0}};
        end else begin
            if (upd_commit_i) begin
                armed_q <= 1'b1;
                stamp_q <= upd_stamp_i;
            end
            if (ce) begin
                if (armed_q && k_q >= stamp_q) begin
                    for (idx = 0; idx < ROWS * COLS; idx = idx + 1) g_q[idx] = gp_q[idx];
                    for (idx = 0; idx < COLS; idx = idx + 1) w_q[idx] = wp_q[idx];
                    if (!upd_commit_i) armed_q <= 1'b0;
                end
                // the row words of sample k - delay: read the line, then write sample k
                for (r = 0; r < ROWS; r = r + 1) begin
                    dac_d[r*DAC_BITS +: DAC_BITS] = (delay == 32'd0) ? dac_i[r*DAC_BITS +: DAC_BITS]
                        : dline[((k_q - delay) % DELAY_MAX) * ROWS + r];
                    dline[(k_q % DELAY_MAX) * ROWS + r] = dac_i[r*DAC_BITS +: DAC_BITS];
                end
                // DC and the common oscillators (every column), the charger sum
                common = fx_common(k_q);
                chg    = fx_osc(k_q, 1'b1);
                clip_any = 1'b0;
                for (c = 0; c < COLS; c = c + 1) begin
                    acc = 64'sd0;
                    for (r = 0; r < ROWS; r = r + 1)
                        acc = acc + $signed(dac_d[r*DAC_BITS +: DAC_BITS])
                                  * $signed({1'b0, g_q[r * COLS + c]});
                    acc = acc + fx_noise(k_q, c[7:0]) + common
                              + ((chg * $signed({{(64 - COUP_BITS){1'b0}}, w_q[c]})) >>> 12);
                    nz  = {{(64 - NOISE_BITS){noise[(k_q % NOISE_LEN) * COLS + c][NOISE_BITS-1]}},
                           noise[(k_q % NOISE_LEN) * COLS + c]};
                    acc = acc + (nz <<< (COUP_FRAC - NOISE_FRAC));
                    y   = (acc + HALF) >>> COUP_FRAC;
                    if (y > HI) begin y = HI; clip_any = 1'b1; end
                    if (y < LO) begin y = LO; clip_any = 1'b1; end
                    y = y & ~enob_msk;
                    adc_o[c*ADC_BITS +: ADC_BITS] <= y[ADC_BITS-1:0];
                end
                clip_o   <= clip_any;
                if (clip_any) clip_sticky_o <= 1'b1;
                sample_o <= k_q;
                k_q      <= k_q + 32'd1;
            end
        end
    end
    /* verilator lint_on BLKSEQ */

endmodule

`default_nettype wire
