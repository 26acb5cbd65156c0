// fmt_rx_array -- the receive back end of all columns: COLS/2 fmt_col_pair_rx in
// lockstep (column 2p is lane a, 2p+1 lane b of pair p; COLS must be even), one shared
// receive PN sign, emitting the HEAT-MAP STREAM of docs/ARCHITECTURE.md:
//   hm_valid  one whole row (all COLS cells) for one clk cycle, rows in the order their
//             comb pair completes in the FFT's bit-reversed output, each row once per frame
//   hm_row    row index, hm_frame frame number (wraps, FRAME_W bits, from 0 after reset)
//   hm_data   column c at [c*HM_W +: HM_W], unsigned
//   hm_eof    one clk cycle after the frame's last row (POST_CLK = 0: one ce period after);
//             never with a row (rows are at least one ce period apart)
// The stream registers run on clk; at most one beat per ce period.  Frame = M = 2^m_log2_i
// windows (see fmt_col_pair_rx); a reset in the middle of a window drops it and the
// stream restarts with the first full frame.
// Latency: fmt_col_pair_rx + 1 clk (stream register): N = 256, ce = 1: the last row
// 292 fs cycles after the window's last ADC sample, hm_eof 293; at 3 x fs (POST_CLK = 1)
// 840 / 841 clk = 280.0 / 280.3 fs cycles (tb/fmt_rx_array measures it).
// Flags (sticky until reset): fft_ovf_o = OR of the FFTs' saturation flags, sat_o = OR
// of the heat-map cell saturations; ovf_o = either (the magnitude cannot overflow).
// Twin: sim/fmt/rx_fixed.py rx_heatmaps_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_rx_array #(
    parameter ROWS       = `FMT_ROWS,      // rows (comb bins)
    parameter COLS       = `FMT_COLS,      // columns (even)
    parameter LOG2_N     = `FMT_LOG2_N,    // FFT size N = 2^LOG2_N
    parameter BIN_LO     = `FMT_BIN_LO,    // bin of row 0
    parameter BIN_STEP   = `FMT_BIN_STEP,  // bins between rows
    parameter ADC_BITS   = `FMT_ADC_BITS,  // ADC word width (signed)
    parameter HM_W       = `FMT_HM_W,      // heat-map cell width (unsigned)
    parameter FRAME_W    = 16,             // frame counter width
    parameter M_LOG2_MAX = 3,              // largest log2 M
    parameter TW_DIR     = "rtl/",         // directory of the FFT twiddle hex files
    parameter POST_CLK   = 1,              // back end after the FFT on every clk (see fmt_col_pair_rx)
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,      // row index width
    parameter SH_W       = (M_LOG2_MAX > 0) ? $clog2(M_LOG2_MAX + 1) : 1  // width of m_log2_i
) (
    input  wire                     clk,
    input  wire                     rst,       // synchronous, active high
    input  wire                     ce,        // sample strobe
    input  wire [COLS*ADC_BITS-1:0] adc_i,     // column c ADC sample at [c*ADC_BITS +: ADC_BITS]
    input  wire                     rx_sign_i, // receive PN sign (fmt_pn_gen rx_sign_o)
    input  wire [SH_W-1:0]          m_log2_i,  // log2 of windows per frame (0 = M = 1)
    output reg                      hm_valid,  // heat-map row beat
    output reg  [ROW_W-1:0]         hm_row,    // row index
    output reg  [FRAME_W-1:0]       hm_frame,  // frame number
    output reg  [COLS*HM_W-1:0]     hm_data,   // the row's cells
    output reg                      hm_eof,    // end of frame marker
    output wire                     fft_ovf_o, // sticky: an FFT saturated
    output wire                     sat_o,     // sticky: a heat-map cell saturated
    output wire                     ovf_o      // sticky: either of the above
);

    localparam PAIRS = COLS / 2;

    wire [PAIRS-1:0]        p_valid, p_last, p_ovf, p_sat;
    wire [PAIRS*ROW_W-1:0]  p_row;
    wire [COLS*HM_W-1:0]    p_hm;

    genvar p;
    generate
        for (p = 0; p < PAIRS; p = p + 1) begin : g_pair
            fmt_col_pair_rx #(
                .LOG2_N(LOG2_N), .ROWS(ROWS), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
                .ADC_BITS(ADC_BITS), .HM_W(HM_W), .M_LOG2_MAX(M_LOG2_MAX),
                .TW_DIR(TW_DIR), .POST_CLK(POST_CLK), .ROW_W(ROW_W), .SH_W(SH_W)
            ) u_pair (
                .clk(clk), .rst(rst), .ce(ce),
                .adc_a_i(adc_i[(2*p)*ADC_BITS +: ADC_BITS]),
                .adc_b_i(adc_i[(2*p+1)*ADC_BITS +: ADC_BITS]),
                .rx_sign_i(rx_sign_i), .m_log2_i(m_log2_i),
                .out_valid(p_valid[p]), .out_row(p_row[p*ROW_W +: ROW_W]),
                .out_hm(p_hm[2*p*HM_W +: 2*HM_W]), .out_last_row(p_last[p]),
                .fft_ovf_o(p_ovf[p]), .sat_o(p_sat[p]));
        end
    endgenerate

    assign fft_ovf_o = |p_ovf;
    assign sat_o     = |p_sat;
    assign ovf_o     = fft_ovf_o | sat_o;

    // the pairs run in lockstep: pair 0's valid, row and last-row mark stand for all
    // (the others' are identical)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [PAIRS-1:0]       unused_valid = p_valid;
    wire [PAIRS*ROW_W-1:0] unused_row   = p_row;
    wire [PAIRS-1:0]       unused_last  = p_last;
    /* verilator lint_on UNUSEDSIGNAL */

    reg ce_q;          // the pair outputs were updated on the last edge (POST_CLK = 0)
    reg eof_pend_q;    // the frame's last row has gone out, hm_eof follows
    // POST_CLK = 1: the pair outputs are one-clk pulses; 0: held for a ce period, new
    // on the clk after a ce edge
    wire fresh = (POST_CLK != 0) ? 1'b1 : ce_q;

    always @(posedge clk) begin
        if (rst) begin
            ce_q       <= 1'b0;
            eof_pend_q <= 1'b0;
            hm_valid   <= 1'b0;
            hm_eof     <= 1'b0;
            hm_frame   <= {FRAME_W{1'b0}};
        end else begin
            ce_q     <= ce;
            hm_valid <= 1'b0;
            hm_eof   <= 1'b0;
            if (fresh && p_valid[0]) begin
                hm_valid <= 1'b1;
                if (p_last[0]) eof_pend_q <= 1'b1;
            end else if (fresh && eof_pend_q) begin
                hm_eof     <= 1'b1;
                eof_pend_q <= 1'b0;
            end
            if (hm_eof) hm_frame <= hm_frame + 1'b1;
        end
    end

    always @(posedge clk) begin
        if (fresh && p_valid[0]) begin
            hm_row  <= p_row[ROW_W-1:0];
            hm_data <= p_hm;
        end
    end

endmodule

`default_nettype wire
