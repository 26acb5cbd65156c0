// Reference only: not instantiated by fmt_core; kept as the documented, tested reference of
// one column pair's whole receive chain with its own magnitude units and accumulator
// (rx_fixed.rx_heatmaps_fixed on two columns, tb/fmt_col_pair_rx); fmt_rx_array shares them.
// fmt_col_pair_rx -- receiver of two real columns a, b sharing one complex FFT:
// despread (x2) -> fmt_fft_r22sdf (z = a + j b) -> fmt_pair_split -> fmt_magnitude (x2,
// one per column: a completed pair needs |A| and |B| in the same ce cycle) ->
// fmt_accum (M = 2^m windows per frame) -> one row of two heat-map cells per beat.
//
// Scaling: the FFT output is rounded to FFT_OUT_W bits, X * 2^-S with
// S = max(0, ADC_BITS + LOG2_N - 2 - HM_W); with HM_SHIFT = 1 a cell is
//   hm = |X_col[k]| * 2^-S  (mean over the M windows, round half up, saturating)
// so a full-scale tone (amplitude 2^(ADC_BITS-1), |X| = 2^(ADC_BITS+LOG2_N-2)) just
// reaches 2^HM_W (amplitude 2047 of 12 bits gives 65504 at every size with S > 0).
// Defaults: N = 256 -> S = 2, FFT_OUT_W = 20, magnitude 21 bits.
//
// Frames: window k is ADC samples k*N .. k*N + N-1 counted from the first ce after
// reset (the FFT is held in reset for that ce while the despreaders fill); a frame
// is M = 2^m_log2_i consecutive windows (m_log2_i sampled at the first window of each
// frame, values above M_LOG2_MAX are clamped).  Rows leave in the order their pair
// completes in the FFT's bit-reversed output (sim/fmt/rx_array.py row_order), only in
// the last window of a frame.
// Latency (M = 1), from the ce edge that takes a window's last ADC sample: the pair
// split takes slot s of the window on the ce edge LATENCY0 + s + 1 ce cycles later
// (LATENCY0 of fmt_fft_r22sdf = 22 at N = 256 with the output rounding, counted from
// its input register, which the despread register feeds); magnitude ITER + 3 and
// accum 2 stages follow, on every clk (POST_CLK = 1: 17 clk) or on ce (POST_CLK = 0).
// Last row at N = 256: 274 ce cycles + 17 clk (ce = 1: 291 cycles; 3 x fs: 839 clk).
// With POST_CLK = 1 out_valid_o is a one-clk pulse, else it is held for the ce period.
// Flags (sticky until reset): fft_ovf_o (FFT internal saturation), sat_o (a cell
// clipped at 2^HM_W - 1).  The magnitude cannot overflow (fmt_magnitude).
// Structure: fmt_rx_pair_front (despread, FFT, bookkeeping, split) + this pair's own
// magnitude units and accumulator.  fmt_rx_array uses the front only and shares a few
// magnitude units and one accumulator memory among all pairs.
// Twin: sim/fmt/rx_array.py rx_heatmaps_fixed (columns of one pair).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_col_pair_rx #(
    parameter LOG2_N     = `FMT_LOG2_N,    // FFT size N = 2^LOG2_N
    parameter ROWS       = `FMT_ROWS,      // comb bins (rows)
    parameter BIN_LO     = `FMT_BIN_LO,    // bin of row 0
    parameter BIN_STEP   = `FMT_BIN_STEP,  // bins between rows
    parameter ADC_BITS   = `FMT_ADC_BITS,  // ADC word width (signed)
    parameter HM_W       = `FMT_HM_W,      // heat-map cell width (unsigned)
    parameter M_LOG2_MAX = 3,              // largest log2 M (M = 1, 2, 4, 8 by default)
    parameter MAG_ITER   = 12,             // CORDIC iterations of fmt_magnitude
    parameter FFT_SHIFT  = (ADC_BITS + LOG2_N - 2 > HM_W) ? ADC_BITS + LOG2_N - 2 - HM_W : 0, // S
    parameter FFT_OUT_W  = ADC_BITS + LOG2_N + 2 - FFT_SHIFT,  // FFT output width (X * 2^-S)
    parameter POST_CLK   = 1,              // 1: split/magnitude/accum advance on every clk (lower
                                           //    latency at CLK_PER_SAMPLE > 1), 0: on ce
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,      // row index width
    parameter SH_W       = (M_LOG2_MAX > 0) ? $clog2(M_LOG2_MAX + 1) : 1  // width of m_log2_i
) (
    input  wire                       clk,
    input  wire                       rst,        // synchronous, active high
    input  wire                       ce,         // sample strobe
    input  wire signed [ADC_BITS-1:0] adc_a_i,    // column a ADC sample (even column)
    input  wire signed [ADC_BITS-1:0] adc_b_i,    // column b ADC sample (odd column)
    input  wire                       rx_sign_i,  // receive PN sign (1 = invert), shared
    input  wire [SH_W-1:0]            m_log2_i,   // log2 of windows per frame
    output wire                       out_valid_o, // one row of the pair this ce cycle
    output wire [ROW_W-1:0]           out_row_o,  // row index
    output wire [2*HM_W-1:0]          out_hm_o,   // {cell b, cell a}, unsigned
    output wire                       out_last_row_o, // this row is the frame's last row
    output wire                       fft_ovf_o,  // sticky FFT saturation
    output wire                       sat_o       // sticky heat-map cell saturation
);

    localparam W    = FFT_OUT_W;
    localparam MW   = W + 1;                        // pair split / magnitude width
    localparam FM_MAX = 1 << M_LOG2_MAX;            // the front counts M = 2^m windows
    localparam FMC_W  = M_LOG2_MAX + 1;             // width of M (= $clog2(FM_MAX + 1))
    localparam TAGW = ROW_W + 2 + FMC_W;            // {row, M, first, last}
    localparam [SH_W-1:0] SH_MAX = M_LOG2_MAX;

    // M = 2^m (m clamped to M_LOG2_MAX) for the front's window counter
    wire [SH_W-1:0]  m_sh;
    generate
        if (M_LOG2_MAX < (1 << SH_W) - 1) begin : g_clamp
            assign m_sh = (m_log2_i > SH_MAX) ? SH_MAX : m_log2_i;
        end else begin : g_noclamp
            assign m_sh = m_log2_i;                 // every SH_W-bit value is <= M_LOG2_MAX
        end
    endgenerate
    wire [FMC_W-1:0] m_pow = {{(FMC_W-1){1'b0}}, 1'b1} << m_sh;

    // ---- despread, FFT, frame bookkeeping, pair split (shared with fmt_rx_array) ----
    wire                 ps_valid;
    wire [ROW_W-1:0]     ps_row;
    wire signed [MW-1:0] ps_ar, ps_ai, ps_br, ps_bi;
    wire [FMC_W+1:0]     ps_tag;
    // the front's result memory serves shared magnitude units (fmt_rx_array); here the
    // split outputs feed this pair's own units: no result memory (RES_MEM = 0)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [4*MW-1:0]      unused_rd;
    /* verilator lint_on UNUSEDSIGNAL */
    fmt_rx_pair_front #(
        .LOG2_N(LOG2_N), .ROWS(ROWS), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .ADC_BITS(ADC_BITS), .M_MAX(FM_MAX), .FFT_OUT_W(W),
        .POST_CLK(POST_CLK), .RES_MEM(0), .ROW_W(ROW_W), .MC_W(FMC_W)
    ) u_front (
        .clk(clk), .rst(rst), .ce(ce), .adc_a_i(adc_a_i), .adc_b_i(adc_b_i),
        .rx_sign_i(rx_sign_i), .m_i(m_pow),
        .ps_valid_o(ps_valid), .ps_row_o(ps_row), .ps_tag_o(ps_tag),
        .ps_ar_o(ps_ar), .ps_ai_o(ps_ai), .ps_br_o(ps_br), .ps_bi_o(ps_bi),
        .rd_row_i({ROW_W{1'b0}}), .rd_data_o(unused_rd), .fft_ovf_o(fft_ovf_o));

    // the stages after the split run on every clk (POST_CLK = 1) or on ce (POST_CLK = 0)
    wire post_ce = (POST_CLK != 0) ? 1'b1 : ce;

    // ---- magnitudes ----
    wire             mg_valid;
    wire [MW-1:0]    mag_a, mag_b;
    wire [TAGW-1:0]  mg_tag;
    // unit b runs in lockstep with unit a: its valid and tag equal a's and are not used
    /* verilator lint_off UNUSEDSIGNAL */
    wire             mg_valid_b;
    wire             mg_tag_b;
    /* verilator lint_on UNUSEDSIGNAL */
    fmt_magnitude #(.IN_W(MW), .ITER(MAG_ITER), .TAG_W(TAGW)) u_mag_a (
        .clk(clk), .rst(rst), .ce(post_ce), .in_valid_i(ps_valid), .in_re_i(ps_ar), .in_im_i(ps_ai),
        .in_tag_i({ps_row, ps_tag}), .out_valid_o(mg_valid), .out_mag_o(mag_a), .out_tag_o(mg_tag));
    fmt_magnitude #(.IN_W(MW), .ITER(MAG_ITER), .TAG_W(1)) u_mag_b (
        .clk(clk), .rst(rst), .ce(post_ce), .in_valid_i(ps_valid), .in_re_i(ps_br), .in_im_i(ps_bi),
        .in_tag_i(1'b0), .out_valid_o(mg_valid_b), .out_mag_o(mag_b), .out_tag_o(mg_tag_b));

    // ---- accumulation over the frame ----
    wire [ROW_W-1:0] mg_row   = mg_tag[TAGW-1 -: ROW_W];
    wire [FMC_W-1:0] mg_m     = mg_tag[FMC_W+1:2];
    reg  [SH_W-1:0]  mg_shift;                       // log2 M (M is a power of two here)
    integer b;
    always @* begin
        mg_shift = {SH_W{1'b0}};
        for (b = 1; b <= M_LOG2_MAX; b = b + 1)
            if (mg_m[b]) mg_shift = b[SH_W-1:0];
    end
    wire             mg_first = mg_tag[1];
    wire             mg_last  = mg_tag[0];
    fmt_accum #(
        .ROWS(ROWS), .LANES(2), .D_W(MW), .M_LOG2_MAX(M_LOG2_MAX), .HM_W(HM_W),
        .HM_SHIFT(1), .ROW_W(ROW_W), .SH_W(SH_W)
    ) u_acc (
        .clk(clk), .rst(rst), .ce(post_ce),
        .in_valid_i(mg_valid), .in_row_i(mg_row), .in_data_i({mag_b, mag_a}),
        .in_first_i(mg_first), .in_last_i(mg_last), .in_shift_i(mg_shift),
        .out_valid_o(out_valid_o), .out_row_o(out_row_o), .out_data_o(out_hm_o), .sat_o(sat_o));

    // the frame's last row is the row whose pair completes last (a constant)
    `include "fmt_rx_last_row.vh"
    localparam LAST_ROW = last_row_f(0);
    assign out_last_row_o = (out_row_o == LAST_ROW[ROW_W-1:0]);

endmodule

`default_nettype wire
