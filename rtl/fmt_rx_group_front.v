// fmt_rx_group_front -- front half of NP <= G column-pair receivers that share ONE
// time-multiplexed FFT engine (fmt_fft_r22sdf CH = G) and one pair split: capture,
// despread, FFT, pair split, window / frame bookkeeping and the pairs' result memories
// (fmt_rx_array with FFT_CH = G; fmt_rx_pair_front is the one-pair-per-engine form).
//
// Sequencing: the ce edge that takes ADC sample k latches the 2 NP columns and the
// receive PN sign (capture registers); on the G clk cycles after it the engine takes
// pair 0, 1, .., G-1 (channel c on cycle c + 1 after the ce cycle; pairs NP .. G-1 of a
// partly used engine get zeros), each despread on the way in (sign ? -x : x, ADC_BITS + 1
// bits, the arithmetic of fmt_despread, one negation per engine lane instead of one per
// column).  So ce must come at most once every G clk cycles: a ce before the G steps of
// the previous sample are done sets the sticky seq_ovf_o (the samples are then lost).
// The FFT, the split and the result memories advance on the engine's steps / every clk.
//
// Frames and tags as fmt_rx_pair_front: window k = ADC samples k*N .. k*N + N-1 counted
// from the first ce after reset; M = m_i windows per frame, any 1 .. M_MAX (sampled when
// channel 0 starts a frame's first window; 0 is taken as 1, values above M_MAX are
// clamped to M_MAX); ps_tag = {M, first window, last window}.
// Timing: channel c of ADC sample j enters the FFT input register on the edge c + 1
// clk after sample j's ce edge (step j G + c); its window's slot s leaves the FFT on step
// t_c + LATENCY0 + s G (fmt_fft_r22sdf), the split decodes it on that step's edge and
// registers the pair's output three clk later (fmt_pair_split, 4 stages on every clk:
// its held memory is block RAM with a registered read at G >= 3, else 2 stages);
// ps_* show it from the next clk (ps_ch_o = c); the result memory of pair c is written
// on the next edge.  The result memories are block RAM with a registered read:
// rd_data_o = the row rd_row_i named two clk earlier (read latch, output register),
// each column's half zero unless its rd_en_i bit was set one clk earlier.  With
// ce every G clk (the 3 x fs build) the steps are consecutive clk cycles, so pair c's
// row r leaves c clk after pair 0's, LATENCY0 + slot_r samples after the window minus
// LATENCY0 (G - 1) clk (the register stages count clk cycles, not samples).
// Formats: FFT output W = FFT_OUT_W bits = X * 2^-FFT_SHIFT (see fmt_col_pair_rx);
// split outputs 2A, 2B exact, W + 1 bits signed.  Flags: fft_ovf_o, seq_ovf_o sticky.
// Twin: sim/fmt/rx_array.py (values rx_heatmaps_fixed, timing rx_row_beats).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_rx_group_front #(
    parameter LOG2_N     = `FMT_LOG2_N,    // FFT size N = 2^LOG2_N
    parameter ROWS       = `FMT_ROWS,      // comb bins (rows)
    parameter BIN_LO     = `FMT_BIN_LO,    // bin of row 0
    parameter BIN_STEP   = `FMT_BIN_STEP,  // bins between rows
    parameter ADC_BITS   = `FMT_ADC_BITS,  // ADC word width (signed)
    parameter M_MAX      = 255,            // largest windows per frame M (<= 255)
    parameter FFT_OUT_W  = 20,             // FFT output width W (X * 2^-S, see fmt_col_pair_rx)
    parameter G          = 3,              // column pairs per engine (FFT channels), >= 2
    parameter NP         = G,              // pairs actually connected, 1..G
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,      // row index width
    parameter MC_W       = $clog2(M_MAX + 1), // width of m_i
    parameter CH_W       = (G > 1) ? $clog2(G) : 1,             // channel index width
    parameter FFT_BRAM_MIN = 48            // FFT delay lines this long or longer in block RAM
                                           // (N = 256, G = 3: 384, 192, 96 and 48 deep)
) (
    input  wire                       clk,
    input  wire                       rst,        // synchronous, active high
    input  wire                       ce,         // sample strobe, at most one per G clk
    input  wire [2*NP*ADC_BITS-1:0]   adc_i,      // pair j: column a at [2j*ADC_BITS], b at [(2j+1)*ADC_BITS]
    input  wire                       rx_sign_i,  // receive PN sign (1 = invert), shared
    input  wire [MC_W-1:0]            m_i,        // windows per frame M (0 = 1, > M_MAX = M_MAX)
    output wire                       ps_valid_o, // a row of pair ps_ch_o completed (split output valid)
    output wire [CH_W-1:0]            ps_ch_o,    // its pair within the group (channel)
    output wire [ROW_W-1:0]           ps_row_o,   // its row index
    output wire [MC_W+1:0]            ps_tag_o,   // {M, first window, last window}
    input  wire [ROW_W-1:0]           rd_row_i,   // result memory read address (row), read 2 clk later
    input  wire [2*NP-1:0]            rd_en_i,    // per column (pair j: a at 2j, b at 2j+1): its half of
                                                  // the output register takes the read latch, else clears
    output wire [NP*(4*FFT_OUT_W+4)-1:0] rd_data_o, // pair j: {2 Im B, 2 Re B, 2 Im A, 2 Re A} at [j*4*(W+1)]
    output wire                       fft_ovf_o,  // sticky FFT saturation
    output reg                        seq_ovf_o   // sticky: ce came before the G steps were done
);

    localparam W  = FFT_OUT_W;
    localparam MW = W + 1;
    localparam XW = ADC_BITS + 1;
    localparam integer        GM1  = G - 1;
    localparam [CH_W-1:0]     CH_LAST = GM1[CH_W-1:0];

    // ---- capture (on ce) and step sequencer ----
    reg [2*NP*ADC_BITS-1:0] cap_q;
    reg                     sign_q;
    reg                     run_q;       // the engine steps this clk
    reg [CH_W-1:0]          ch_q;        // channel (pair) of this step

    always @(posedge clk) begin
        if (ce) begin
            cap_q  <= adc_i;
            sign_q <= rx_sign_i;
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            run_q     <= 1'b0;
            ch_q      <= {CH_W{1'b0}};
            seq_ovf_o <= 1'b0;
        end else if (ce) begin
            run_q <= 1'b1;
            ch_q  <= {CH_W{1'b0}};
            if (run_q && ch_q != CH_LAST) seq_ovf_o <= 1'b1;
        end else if (run_q) begin
            if (ch_q == CH_LAST) run_q <= 1'b0;
            else                 ch_q  <= ch_q + 1'b1;
        end
    end

    // synthesis translate_off
    always @(posedge clk) begin
        if (!rst && ce && run_q && ch_q != CH_LAST)
            $display("%m: ERROR: ce at %0t before the %0d engine steps of the previous sample", $time, G);
    end
    // synthesis translate_on

    // ---- channel select and despread: x = sign ? -adc : adc (ADC_BITS + 1 bits) ----
    reg signed [ADC_BITS-1:0] sel_a, sel_b;
    integer j;
    always @* begin
        sel_a = {ADC_BITS{1'b0}};
        sel_b = {ADC_BITS{1'b0}};
        for (j = 0; j < NP; j = j + 1) begin
            if (ch_q == j[CH_W-1:0]) begin
                sel_a = cap_q[(2*j)*ADC_BITS +: ADC_BITS];
                sel_b = cap_q[(2*j+1)*ADC_BITS +: ADC_BITS];
            end
        end
    end
    wire signed [XW-1:0] ext_a = {sel_a[ADC_BITS-1], sel_a};
    wire signed [XW-1:0] ext_b = {sel_b[ADC_BITS-1], sel_b};
    wire signed [XW-1:0] xa    = sign_q ? -ext_a : ext_a;
    wire signed [XW-1:0] xb    = sign_q ? -ext_b : ext_b;

    // ---- FFT: G channels ----
    wire                f_valid;
    wire [LOG2_N-1:0]   f_slot, f_bin;
    wire [CH_W-1:0]     f_ch;
    wire signed [W-1:0] f_re, f_im;
    fmt_fft_r22sdf #(
        .LOG2_N(LOG2_N), .IN_W(XW), .OUT_W(W), .CH(G), .CH_W(CH_W),
        .BRAM_MIN(FFT_BRAM_MIN)
    ) u_fft (
        .clk(clk), .rst(rst), .ce(run_q), .in_re_i(xa), .in_im_i(xb),
        .out_valid_o(f_valid), .out_slot_o(f_slot), .out_bin_o(f_bin),
        .out_re_o(f_re), .out_im_o(f_im), .out_ch_o(f_ch), .ovf_o(fft_ovf_o));

    // ---- window / frame bookkeeping (at the FFT output; channel 0 opens a window) ----
    wire                 new_win = f_valid && (f_slot == {LOG2_N{1'b0}}) && (f_ch == {CH_W{1'b0}});
    wire [MC_W-1:0]      m_cur;                     // M of the current frame
    wire                 w_first, w_last;           // first / last window of the frame
    fmt_rx_frame_win #(.M_MAX(M_MAX), .MC_W(MC_W)) u_win (
        .clk(clk), .rst(rst), .en_i(1'b1), .win_i(new_win), .m_i(m_i),
        .m_cur_o(m_cur), .w_first_o(w_first), .w_last_o(w_last));

    // ---- pair split, shared by the G channels ----
    wire signed [MW-1:0] s_ar, s_ai, s_br, s_bi;
    fmt_pair_split #(
        .LOG2_N(LOG2_N), .ROWS(ROWS), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
        .W(W), .TAG_W(MC_W + 2), .ROW_W(ROW_W), .CH(G), .CH_W(CH_W)
    ) u_split (
        .clk(clk), .rst(rst), .ce(1'b1),
        .in_valid_i(f_valid), .in_bin_i(f_bin), .in_re_i(f_re), .in_im_i(f_im),
        .in_tag_i({m_cur, w_first, w_last}), .in_ch_i(f_ch),
        .out_valid_o(ps_valid_o), .out_row_o(ps_row_o),
        .a_re_o(s_ar), .a_im_o(s_ai), .b_re_o(s_br), .b_im_o(s_bi), .out_tag_o(ps_tag_o),
        .out_ch_o(ps_ch_o));

    // ---- result memories, one per pair, in block RAM (read by the shared magnitude
    // units): the read latch takes res_mem[rd_row_i] on every clk; one clk later each
    // column's half of the output register (rd_data_o) takes the latch when its
    // rd_en_i bit is set, else clears (its flip-flops' synchronous reset): a column is
    // non-zero only in the step the units take it, so fmt_rx_array selects a cell with an
    // OR instead of a multiplexer
    genvar p;
    generate
        for (p = 0; p < NP; p = p + 1) begin : g_res
            (* ram_style = "block" *) reg [4*MW-1:0] res_mem [0:ROWS-1];
            reg [4*MW-1:0] rd_lat_q;
            reg [2*MW-1:0] rd_a_q, rd_b_q;         // block-RAM output register, per column
            always @(posedge clk) begin
                if (ps_valid_o && ps_ch_o == p[CH_W-1:0])
                    res_mem[ps_row_o] <= {s_bi, s_br, s_ai, s_ar};
                rd_lat_q <= res_mem[rd_row_i];
            end
            always @(posedge clk) begin
                if (rd_en_i[2*p]) rd_a_q <= rd_lat_q[2*MW-1:0];
                else              rd_a_q <= {(2*MW){1'b0}};
                if (rd_en_i[2*p+1]) rd_b_q <= rd_lat_q[4*MW-1:2*MW];
                else                rd_b_q <= {(2*MW){1'b0}};
            end
            assign rd_data_o[p*4*MW +: 4*MW] = {rd_b_q, rd_a_q};
        end
    endgenerate

endmodule

`default_nettype wire
