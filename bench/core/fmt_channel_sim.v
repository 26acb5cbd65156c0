// fmt_channel_sim -- SIMULATION-ONLY channel model for full-chain simulations: the
// DDS bank's row words, a ROWS x COLS coupling matrix and additive noise make COLS
// ADC samples per sample strobe.  Not synthesizable by intent (64-bit arithmetic,
// whole-matrix copies, a file of noise); it lives in bench/core/, not rtl/.
//
// Sample k = k-th ce edge after reset; the row words present at that edge are sample k.
//   acc[c] = sum_r dac[r] * G[r][c]  +  noise[(k mod NOISE_LEN)][c] << (COUP_FRAC - NOISE_FRAC)
//   y[c]   = (acc[c] + 2^(COUP_FRAC-1)) >>> COUP_FRAC          (round half up)
//   adc[c] = clip(y[c], -2^(ADC_BITS-1), 2^(ADC_BITS-1) - 1), clip_o = any column clipped
// G[r][c] is unsigned COUP_BITS with COUP_FRAC fractional bits (in ADC LSB per DAC
// LSB); noise words are signed NOISE_BITS with NOISE_FRAC fractional bits (ADC LSB),
// NOISE_LEN x COLS words, row-major (sample, column), from the $readmemh file
// NOISE_FILE (written by sim/fmt/channel.py write_noise_hex; "" = no noise).
// Output registered: adc_o / clip_o after ce edge k belong to sample k (latency 1).
// clip_sticky_o stays 1 from the first clipped sample until reset.
//
// Coupling updates, stamped with the sample index at which they apply:
//   upd_we_i writes G_pending[upd_row_i][upd_col_i] = upd_data_i (any clk cycle);
//   upd_commit_i arms a copy G := G_pending stamped upd_stamp_i; the copy happens at
//   the first ce edge whose sample index is >= the stamp, and that sample already uses
//   the new G (so a touch can start on its exact onset sample).  One armed copy at a
//   time (a new commit replaces an armed one).  Reset clears the sample counter, the
//   armed copy, the outputs and the sticky flag; G and G_pending keep their contents
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
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,  // width of upd_row_i
    parameter COL_W      = (COLS > 1) ? $clog2(COLS) : 1   // width of upd_col_i
) (
    input  wire                      clk,
    input  wire                      rst,            // synchronous, active high
    input  wire                      ce,             // sample strobe
    input  wire [ROWS*DAC_BITS-1:0]  dac_i,          // row r at [r*DAC_BITS +: DAC_BITS]
    input  wire                      upd_we_i,       // write one pending coupling
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
    reg [31:0]           k_q;
    reg                  armed_q;
    reg [31:0]           stamp_q;

    integer r, c, idx;
    reg signed [63:0] acc, y, nz;
    reg               clip_any;

    localparam signed [63:0] HI = (64'sd1 <<< (ADC_BITS - 1)) - 1;
    localparam signed [63:0] LO = -(64'sd1 <<< (ADC_BITS - 1));
    localparam signed [63:0] HALF = (COUP_FRAC > 0) ? (64'sd1 <<< (COUP_FRAC - 1)) : 64'sd0;

    initial begin
        for (idx = 0; idx < ROWS * COLS; idx = idx + 1) begin
            g_q[idx]  = {COUP_BITS{1'b0}};
            gp_q[idx] = {COUP_BITS{1'b0}};
        end
        for (idx = 0; idx < NOISE_LEN * COLS; idx = idx + 1) noise[idx] = {NOISE_BITS{1'b0}};
        if (NOISE_FILE != "") $readmemh(NOISE_FILE, noise);
    end

    // Simulation model: blocking temporaries (acc, y, the matrix copy) inside the
    // clocked process are intended; nothing else reads them.
    /* verilator lint_off BLKSEQ */
    always @(posedge clk) begin
        if (upd_we_i && upd_row_i < ROWS && upd_col_i < COLS)
            gp_q[upd_row_i * COLS + upd_col_i] <= upd_data_i;
        if (rst) begin
            k_q           <= 32'd0;
            armed_q       <= 1'b0;
            adc_o         <= {(COLS * ADC_BITS){1'b0}};
            clip_o        <= 1'b0;
            clip_sticky_o <= 1'b0;
            sample_o      <= 32'd0;
        end else begin
            if (upd_commit_i) begin
                armed_q <= 1'b1;
                stamp_q <= upd_stamp_i;
            end
            if (ce) begin
                if (armed_q && k_q >= stamp_q) begin
                    for (idx = 0; idx < ROWS * COLS; idx = idx + 1) g_q[idx] = gp_q[idx];
                    if (!upd_commit_i) armed_q <= 1'b0;
                end
                clip_any = 1'b0;
                for (c = 0; c < COLS; c = c + 1) begin
                    acc = 64'sd0;
                    for (r = 0; r < ROWS; r = r + 1)
                        acc = acc + $signed(dac_i[r*DAC_BITS +: DAC_BITS])
                                  * $signed({1'b0, g_q[r * COLS + c]});
                    nz  = {{(64 - NOISE_BITS){noise[(k_q % NOISE_LEN) * COLS + c][NOISE_BITS-1]}},
                           noise[(k_q % NOISE_LEN) * COLS + c]};
                    acc = acc + (nz <<< (COUP_FRAC - NOISE_FRAC));
                    y   = (acc + HALF) >>> COUP_FRAC;
                    if (y > HI) begin y = HI; clip_any = 1'b1; end
                    if (y < LO) begin y = LO; clip_any = 1'b1; end
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
