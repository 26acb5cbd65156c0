// fmt_rx_pair_front -- front half of a column-pair receiver: despread (x2) ->
// fmt_fft_r22sdf (z = a + j b) -> fmt_pair_split, with the window / frame bookkeeping,
// plus a ROWS-entry result memory that keeps each row's (2A, 2B) until the row's next
// completion one window later, so that magnitude units shared by many pairs can read it
// at their own pace (fmt_rx_array with FFT_CH = 1; with FFT_CH = G > 1 the array uses
// fmt_rx_group_front, one time-multiplexed FFT engine per G pairs).  fmt_col_pair_rx
// adds its own magnitude units and accumulator to the split outputs (its result memory
// is then unused and trimmed).
//
// Frames: window k is ADC samples k*N .. k*N + N-1 counted from the first ce after reset
// (the FFT is held in reset for that ce while the despreaders fill); a frame is
// M = m_i consecutive windows, any 1 .. M_MAX (m_i sampled at the first window of a
// frame; 0 is taken as 1, values above M_MAX are clamped).  ps_tag = {M, first window,
// last window}.
// Timing: the pair split takes slot s of a window on the ce edge LATENCY0 + s + 1 ce
// cycles after the ce edge that takes the window's last ADC sample (LATENCY0 of
// fmt_fft_r22sdf, counted from its input register which the despread register feeds);
// ps_* are registered by the split one post_ce edge later (its second stage); the
// result memory is written on the
// next post_ce edge (rd_data_o shows it from then on, asynchronous read: LUT RAM).
// Formats: FFT output W = FFT_OUT_W bits = X * 2^-FFT_SHIFT (see fmt_col_pair_rx);
// split outputs 2A, 2B exact, W + 1 bits signed.  Flag: fft_ovf_o sticky.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_rx_pair_front #(
    parameter LOG2_N     = `FMT_LOG2_N,    // FFT size N = 2^LOG2_N
    parameter ROWS       = `FMT_ROWS,      // comb bins (rows)
    parameter BIN_LO     = `FMT_BIN_LO,    // bin of row 0
    parameter BIN_STEP   = `FMT_BIN_STEP,  // bins between rows
    parameter ADC_BITS   = `FMT_ADC_BITS,  // ADC word width (signed)
    parameter M_MAX      = 255,            // largest windows per frame M (<= 255)
    parameter FFT_OUT_W  = 20,             // FFT output width W (X * 2^-S, see fmt_col_pair_rx)
    parameter POST_CLK   = 1,              // 1: split and result memory on every clk, 0: on ce
    parameter RES_MEM    = 1,              // 1: result memory and read port, 0: none (rd_data_o = 0)
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,      // row index width
    parameter MC_W       = $clog2(M_MAX + 1)    // width of m_i
) (
    input  wire                       clk,
    input  wire                       rst,        // synchronous, active high
    input  wire                       ce,         // sample strobe
    input  wire signed [ADC_BITS-1:0] adc_a_i,    // column a ADC sample (even column)
    input  wire signed [ADC_BITS-1:0] adc_b_i,    // column b ADC sample (odd column)
    input  wire                       rx_sign_i,  // receive PN sign (1 = invert), shared
    input  wire [MC_W-1:0]            m_i,        // windows per frame M (0 = 1, > M_MAX = M_MAX)
    output wire                       ps_valid_o, // a row's pair completed (split output valid)
    output wire [ROW_W-1:0]           ps_row_o,   // its row index
    output wire [MC_W+1:0]            ps_tag_o,   // {M, first window, last window}
    output wire signed [FFT_OUT_W:0]  ps_ar_o,    // 2 Re A (column a)
    output wire signed [FFT_OUT_W:0]  ps_ai_o,    // 2 Im A
    output wire signed [FFT_OUT_W:0]  ps_br_o,    // 2 Re B (column b)
    output wire signed [FFT_OUT_W:0]  ps_bi_o,    // 2 Im B
    input  wire [ROW_W-1:0]           rd_row_i,   // result memory read address (row)
    output wire [4*FFT_OUT_W+3:0]     rd_data_o,  // {2 Im B, 2 Re B, 2 Im A, 2 Re A} of that row
    output wire                       fft_ovf_o   // sticky FFT saturation
);

    localparam W  = FFT_OUT_W;
    localparam MW = W + 1;

    // ---- despread ----
    wire signed [ADC_BITS:0] xa, xb;
    fmt_despread #(.ADC_BITS(ADC_BITS)) u_dsa (
        .clk(clk), .rst(rst), .ce(ce), .adc_i(adc_a_i), .sign_i(rx_sign_i), .y_o(xa));
    fmt_despread #(.ADC_BITS(ADC_BITS)) u_dsb (
        .clk(clk), .rst(rst), .ce(ce), .adc_i(adc_b_i), .sign_i(rx_sign_i), .y_o(xb));

    // ---- FFT ----
    // The despreaders add one ce cycle; the FFT is held in reset through the first ce
    // after reset so that its window 0 is ADC samples 0 .. N-1 (counted from that ce).
    reg fft_rst_q;
    always @(posedge clk) begin
        if (rst)      fft_rst_q <= 1'b1;
        else if (ce)  fft_rst_q <= 1'b0;
    end

    wire                f_valid;
    wire [LOG2_N-1:0]   f_slot, f_bin;
    wire signed [W-1:0] f_re, f_im;
    wire                f_ch;          // one channel: always 0
    fmt_fft_r22sdf #(
        .LOG2_N(LOG2_N), .IN_W(ADC_BITS + 1), .OUT_W(W)
    ) u_fft (
        .clk(clk), .rst(fft_rst_q), .ce(ce), .in_re_i(xa), .in_im_i(xb),
        .out_valid_o(f_valid), .out_slot_o(f_slot), .out_bin_o(f_bin),
        .out_re_o(f_re), .out_im_o(f_im), .out_ch_o(f_ch), .ovf_o(fft_ovf_o));

    // The FFT's out_valid_o is 1 only on ce cycles: its outputs are taken on ce edges; the
    // split registers and the result memory run on every clk (POST_CLK = 1) or on ce.
    wire post_ce = (POST_CLK != 0) ? 1'b1 : ce;

    // ---- window / frame bookkeeping (at the FFT output) ----
    wire                 new_win = f_valid && (f_slot == {LOG2_N{1'b0}});
    wire [MC_W-1:0]      m_cur;                     // M of the current frame
    wire                 w_first, w_last;           // first / last window of the frame
    fmt_rx_frame_win #(.M_MAX(M_MAX), .MC_W(MC_W)) u_win (
        .clk(clk), .rst(rst), .en_i(ce), .win_i(new_win), .m_i(m_i),
        .m_cur_o(m_cur), .w_first_o(w_first), .w_last_o(w_last));

    // ---- pair split ----
    // one channel per engine here (fmt_rx_group_front shares one between column pairs)
    /* verilator lint_off UNUSEDSIGNAL */
    wire ps_ch;
    /* verilator lint_on UNUSEDSIGNAL */
    fmt_pair_split #(
        .LOG2_N(LOG2_N), .ROWS(ROWS), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .W(W), .TAG_W(MC_W + 2), .ROW_W(ROW_W)
    ) u_split (
        .clk(clk), .rst(rst), .ce(post_ce),
        .in_valid_i(f_valid), .in_bin_i(f_bin), .in_re_i(f_re), .in_im_i(f_im),
        .in_tag_i({m_cur, w_first, w_last}),
        .out_valid_o(ps_valid_o), .out_row_o(ps_row_o),
        .a_re_o(ps_ar_o), .a_im_o(ps_ai_o), .b_re_o(ps_br_o), .b_im_o(ps_bi_o), .out_tag_o(ps_tag_o),
        .in_ch_i(f_ch), .out_ch_o(ps_ch));

    // ---- result memory: row r's (2A, 2B), written when the row completes ----
    generate
        if (RES_MEM != 0) begin : g_res
            reg [4*MW-1:0] res_mem [0:ROWS-1];
            always @(posedge clk) begin
                if (post_ce && ps_valid_o) begin
                    res_mem[ps_row_o] <= {ps_bi_o, ps_br_o, ps_ai_o, ps_ar_o};
                end
            end
            assign rd_data_o = res_mem[rd_row_i];
        end else begin : g_nores
            // the split outputs are used directly (fmt_col_pair_rx)
            /* verilator lint_off UNUSEDSIGNAL */
            wire [ROW_W-1:0] unused_rd_row = rd_row_i;
            /* verilator lint_on UNUSEDSIGNAL */
            assign rd_data_o = {(4*MW){1'b0}};
        end
    endgenerate

endmodule

`default_nettype wire
