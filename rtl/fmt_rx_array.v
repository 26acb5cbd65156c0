// fmt_rx_array -- the receive back end of all columns, emitting the HEAT-MAP STREAM of
// docs/ARCHITECTURE.md.  Column pair p = columns 2p (lane a) and 2p+1 (lane b; COLS
// even) shares one complex FFT.  FFT_CH = G > 1 (default G = CLK_PER_SAMPLE when
// POST_CLK = 1): pairs gG .. gG+G-1 share ONE time-multiplexed FFT engine, pair split and
// capture / despread (fmt_rx_group_front; ceil(PAIRS / G) engines, the last may carry
// fewer pairs; 30 x 40 at 3 x fs: 7 engines for 20 pairs); ce must then come at most
// once every G clk (else the sticky overrun is set).  FFT_CH = 1: one
// fmt_rx_pair_front (despread x2, FFT, pair split, result memory) per pair.  All
// engines run in lockstep; MAG_UNITS magnitude units (fmt_magnitude) and ONE
// accumulator memory are shared by all columns:
//   queue   every engine completes a row's comb bins in the same slot, pair c of an
//           engine c clk after its pair 0 (engine 0 stands for all); the row is queued
//           when the last pair has it: {row, M, first, last} enter a FIFO (2^ROW_W
//           entries, LUT RAM)
//   engine  takes a row from the FIFO and reads the pairs' result memories at that row
//           (one address for all pairs), feeding unit u with cell c = g*MAG_UNITS + u in
//           step g = 0 .. P-1, P = ceil(COLS / MAG_UNITS): a row takes P steps
//   accum   the magnitudes keep MAG_FRAC fractional bits (fmt_magnitude FRAC, truncated:
//           the cell below is the chain's one rounding, no bias from rounding twice);
//           one memory of 2^(ROW_W+G_W) x MAG_UNITS*SUM_W bits, address {row, g}
//           (synchronous read: block RAM), exact sum over the M windows (SUM_W = MW +
//           MAG_FRAC + MC_W bits: M_MAX windows cannot overflow), then the rounded mean
//             cell = floor((sum + M F) / 2MF), F = 2^MAG_FRAC  (round half up of sum / 2MF;
//                                  the 2 is the pair split's factor, HM_SHIFT = 1)
//           by an exact reciprocal multiply: t = sum + M F < 2^T (T = SUM_W + 1),
//           l = ceil(log2 M), R = ceil(2^(T+l) / M) (T + 1 bits), cell = (t R) >>
//           (T + l + 1 + MAG_FRAC) = floor(floor(t / M) / 2F) for every t < 2^T (Granlund-Montgomery:
//           R M - 2^(T+l) < M <= 2^l; rx_fixed.recip / recip_divide, tested exhaustively
//           at small T and by the bound for every M at the build's T); for M = 2^m exactly
//           (sum + 2^(m+MAG_FRAC)) >> (m + 1 + MAG_FRAC).  R comes from
//           fmt_recip.hex (rx_fixed.recip_rom: ceil(2^(40+l) / M) for M = 0..255)
//           as ceil(entry / 2^(40-T)) (one add per row).  Then saturate to HM_W bits
//   stream  group g's cells go into the row register at [g*MAG_UNITS*HM_W]; after the
//           last group hm_valid_o is high for one clk with the whole row
// A "step" is a clk (POST_CLK = 1) or a ce cycle (POST_CLK = 0); rows complete at most
// one per ce, in the FFT's bit-reversed order (bursts of two then >= 7 slots at N = 256;
// sim/fmt/rx_array.py row_order).
// MAG_UNITS rule: steps per FFT slot C = CLK_PER_SAMPLE (POST_CLK = 1) or 1 (POST_CLK =
// 0).  The comb's rows complete at most two in any 8 consecutive slots, so with
// P <= 4 C (default K = ceil(COLS / (4 C))) a row waits at most for its burst partner:
// 30 x 40, N = 256: K = 4 at C = 3, K = 10 at C = 1 (rx_fixed.rx_share_schedule checks
// the schedule for the sensor configs).  Elaboration fails (missing module
// fmt_rx_array_MAG_UNITS_too_few) when ROWS * P > N * C (a window's rows cannot be
// processed in a window); at run time (ce faster than CLK_PER_SAMPLE says) a row arriving
// with the queue full or while its previous window's copy is still queued or being fed
// sets the sticky overrun bit, reported in overrun_o.  Twin: rx_fixed.rx_share_schedule.
// Stream: hm_valid_o one clk per row, hm_row_o its index, hm_frame_o the frame number (wraps,
// FRAME_W bits, from 0 after reset), hm_data_o column c at [c*HM_W +: HM_W] (valid with
// hm_valid_o), hm_eof_o one step after the frame's last row, never with a row.  Frame =
// M = m_i windows, any 1 .. M_MAX (latched at a frame's first window; 0 is taken as 1,
// values above M_MAX as M_MAX; fmt_rx_pair_front); a reset in the middle of a window
// drops it and the stream restarts with the first full frame.
// Latency (M = 1), from the ce edge that takes a window's last ADC sample: row r's pair
// split output (the last pair's, FFT_CH > 1) is registered at step a_r: FFT_CH = 1,
// LATENCY0 + slot_r + 2 ce cycles later with POST_CLK = 0, 1 clk after LATENCY0 + slot_r
// + 1 ce cycles with POST_CLK = 1 (the split's second stage runs on clk); FFT_CH = G with
// ce every G clk, clk G + LATENCY0 + G slot_r + 3 (the FFT's register stages step on
// clk cycles; the split's held memory is block RAM with a registered read at G >= 3:
// rx_array.rx_split_clk, split_lat); the row is queued at a_r + 1, loaded at L_r >= a_r + 2,
// and its beat is at step L_r + P + MAG_ITER + 12 + RD_LAT (P unit input steps, with
// FFT_CH > 1 the result memories' block-RAM read latch and output register (RD_LAT = 2;
// 0 with FFT_CH = 1), cell multiplexer register, MAG_ITER + 3 magnitude stages,
// accumulator read and its output register, sum, rounding add, reciprocal partial
// products, their middle sum, the full product, shift + saturate, row register); the
// same for every M (counted from the frame's last window).
// N = 256, 30 x 40: at 3 x fs (K = 4) 819 clk = 273.0 fs cycles with FFT_CH = 3 (859 clk
// with FFT_CH = 1; 815 before the result and held memories moved to block RAM), hm_eof_o
// 1 step later (tb/fmt_rx_array measures them, rx_array.rx_row_beats predicts).
// Pipeline rule: every block-RAM read (accumulator, reciprocal ROM, FFT_CH > 1: the
// pairs' result memories) has its output register, every product its operand and
// product registers (the 2T+1-bit t R as four 17 x 17-bit partial products, then one
// adder per step).
// Flags (sticky until reset, each on its own so a host can tell them apart): fft_ovf_o =
// OR of the FFTs' saturation flags, sat_o = a heat-map cell saturated, overrun_o = a row
// lost to timing: queue full, a row rewritten before it was read, or (FFT_CH > 1) ce
// faster than one per FFT_CH clk (the magnitude cannot overflow).
// Twin: sim/fmt/rx_array.py rx_heatmaps_fixed (values), rx_row_beats (timing).
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
    parameter M_MAX      = 255,            // largest windows per frame M (1 .. 255)
    parameter POST_CLK   = 1,              // 1: back end after the FFT on every clk, 0: on ce
    parameter ROW_W      = (ROWS > 1) ? $clog2(ROWS) : 1,      // row index width
    parameter MC_W       = $clog2(M_MAX + 1),                  // width of m_i
    parameter CLK_PER_SAMPLE = (POST_CLK != 0) ? 3 : 1,   // smallest clk per ce period the
                                           // shared units must keep up with (POST_CLK = 1)
    parameter MAG_ITER   = 12,             // CORDIC iterations of fmt_magnitude
    parameter MAG_FRAC   = 2,              // fractional bits the magnitudes keep (truncated)
                                           // into the sums: the cell is rounded once
    parameter MAG_UNITS  = 0,              // shared magnitude units K; 0 = the default rule
    parameter FFT_CH     = (POST_CLK != 0) ? CLK_PER_SAMPLE : 1  // column pairs per FFT engine
                                           // (time-multiplexed, needs ce at most every
                                           // FFT_CH clk and POST_CLK = 1); 1 = one engine per pair
) (
    input  wire                     clk,
    input  wire                     rst,       // synchronous, active high
    input  wire                     ce,        // sample strobe
    input  wire [COLS*ADC_BITS-1:0] adc_i,     // column c ADC sample at [c*ADC_BITS +: ADC_BITS]
    input  wire                     rx_sign_i, // receive PN sign (fmt_pn_gen rx_sign_o)
    input  wire [MC_W-1:0]          m_i,       // windows per frame M (0 = 1, > M_MAX = M_MAX)
    output reg                      hm_valid_o, // heat-map row beat
    output reg  [ROW_W-1:0]         hm_row_o,  // row index
    output reg  [FRAME_W-1:0]       hm_frame_o, // frame number
    output wire [COLS*HM_W-1:0]     hm_data_o, // the row's cells
    output reg                      hm_eof_o,  // end of frame marker
    output wire                     fft_ovf_o, // sticky: an FFT saturated
    output wire                     sat_o,     // sticky: a heat-map cell saturated
    output wire                     overrun_o  // sticky: a row lost (queue full, rewritten, ce too fast)
);

    localparam PAIRS = COLS / 2;
    localparam N     = 1 << LOG2_N;
    // FFT output scaling: as fmt_col_pair_rx (X * 2^-S, S = ADC_BITS + LOG2_N - 2 - HM_W)
    localparam FFT_SHIFT = (ADC_BITS + LOG2_N - 2 > HM_W) ? ADC_BITS + LOG2_N - 2 - HM_W : 0;
    localparam W     = ADC_BITS + LOG2_N + 2 - FFT_SHIFT;   // FFT output width
    localparam MW    = W + 1;                                // split / magnitude width
    localparam CW    = 2 * MW;                               // one cell {im, re}
    localparam STEPC = (POST_CLK != 0) ? CLK_PER_SAMPLE : 1; // steps per FFT slot

    // ---- the frame's last row (the row whose pair completes last in bit-reversed order)
    `include "fmt_rx_last_row.vh"

    // MAG_UNITS = 0: K = ceil(COLS / (4 * STEPC)), a row in at most 4 steps per FFT slot:
    // the comb's rows complete at most two in any 8 consecutive slots (bit-reversed order;
    // rx_fixed checks it and the resulting schedule for the sensor configs)
    localparam K    = (MAG_UNITS > 0) ? MAG_UNITS :
                      ((COLS + 4 * STEPC - 1) / (4 * STEPC) > 0 ? (COLS + 4 * STEPC - 1) / (4 * STEPC) : 1);
    localparam P    = (COLS + K - 1) / K;                    // steps (groups) per row
    localparam G_W  = (P > 1) ? $clog2(P) : 1;               // group index width
    localparam AW   = ROW_W + G_W;                           // accumulator address {row, g}
    localparam MAGW = MW + MAG_FRAC;                         // magnitude word (MAG_FRAC fraction)
    localparam SUM_W = MAGW + MC_W;                          // exact sum over M_MAX windows
    localparam T    = SUM_W + 1;                             // divider input width (sum + M)
    localparam TR   = 40;                                    // precision of fmt_recip.hex
    localparam RW   = TR + 1;                                // ROM word width
    localparam LW   = 4;                                     // width of l = ceil(log2 M) <= 8
    localparam PW   = 2 * T + 1;                             // product width
    localparam QW   = PW - T - 1 - MAG_FRAC;                 // product >> (T + 1 + MAG_FRAC) width
    localparam TAGW = ROW_W + G_W + MC_W + 2;                // {row, g, M, first, last}
    localparam QD   = 1 << ROW_W;                            // queue depth (>= ROWS)
    localparam LAST_ROW = last_row_f(0);
    localparam integer PM1 = P - 1;
    localparam [G_W-1:0] G_LAST = PM1[G_W-1:0];

    generate
        if (M_MAX < 1 || M_MAX > 255 || T > TR || MAG_FRAC < 0) begin : g_check_m
            // M_MAX outside 1 .. 255 (fmt_recip.hex), the sum too wide for its precision
            // or a negative MAG_FRAC
            fmt_rx_array_M_MAX_unsupported u_bad_m ();
        end
        if (ROWS * P > N * STEPC) begin : g_check
            // MAG_UNITS too few to process a window's rows in a window: stop elaboration
            fmt_rx_array_MAG_UNITS_too_few u_too_few ();
        end
    endgenerate

    // ---- per pair: despread, FFT, pair split, result memory ----
    // FFT_CH = 1: one fmt_rx_pair_front per pair, in lockstep (pair 0 stands for all).
    // FFT_CH = G > 1: one fmt_rx_group_front per G pairs (pairs g G .. g G + G-1 share an
    // engine, the last group may have fewer), all groups in lockstep; pair c of a group
    // completes a row c clk after pair 0 (group 0 stands for all groups): the row is
    // queued when group 0's last pair (channel G-1) has it, the hazard check is done
    // when its first pair (channel 0) rewrites the row.
    localparam GC    = (FFT_CH > 1) ? FFT_CH : 1;
    localparam NGRP  = (PAIRS + GC - 1) / GC;
    localparam GCH_W = (GC > 1) ? $clog2(GC) : 1;
    localparam integer GCM1 = GC - 1;
    localparam [GCH_W-1:0] GCH_LAST = GCM1[GCH_W-1:0];

    wire [P*K*CW-1:0]       cells;       // the engine's row: cell c = {im, re} at [c*CW +: CW]
    reg  [ROW_W-1:0]        row_q;       // engine row (result memory read address)
    wire                    push_v;      // a row is complete in every pair: queue it
    wire [ROW_W-1:0]        push_row;
    wire [MC_W+1:0]         push_tag;
    wire                    chk_v;       // a row's result memories start to be rewritten
    wire [ROW_W-1:0]        chk_row;
    wire                    seq_ovf;     // a time-multiplexed engine missed a sample
    wire [COLS-1:0]         col_en;      // FFT_CH > 1: column c's result register loads (its step)
    wire                    fft_ovf_any;

    generate
        if (GC > 1 && POST_CLK == 0) begin : g_check_ch
            // a shared FFT engine steps on clk cycles: it needs POST_CLK = 1
            fmt_rx_array_FFT_CH_needs_POST_CLK u_bad ();
        end
        if (P * K > COLS) begin : g_pad
            assign cells[P*K*CW-1:COLS*CW] = {((P*K-COLS)*CW){1'b0}};
        end
    endgenerate

    genvar p;
    generate
        if (GC == 1) begin : g_pairs
            wire [PAIRS-1:0]          p_valid, p_ovf;
            wire [PAIRS*ROW_W-1:0]    p_row;
            wire [PAIRS*(MC_W+2)-1:0] p_tag;
            // split outputs are used through the result memories only; the pairs run in
            // lockstep: pair 0's valid, row and tag stand for all
            /* verilator lint_off UNUSEDSIGNAL */
            wire [PAIRS*4*MW-1:0]     p_split;
            wire [PAIRS-1:0]          unused_valid = p_valid;
            wire [PAIRS*ROW_W-1:0]    unused_row   = p_row;
            wire [PAIRS*(MC_W+2)-1:0] unused_tag   = p_tag;
            /* verilator lint_on UNUSEDSIGNAL */
            for (p = 0; p < PAIRS; p = p + 1) begin : g_pair
                fmt_rx_pair_front #(
                    .LOG2_N(LOG2_N), .ROWS(ROWS), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
                    .ADC_BITS(ADC_BITS), .M_MAX(M_MAX), .FFT_OUT_W(W),
                    .POST_CLK(POST_CLK), .ROW_W(ROW_W), .MC_W(MC_W)
                ) u_front (
                    .clk(clk), .rst(rst), .ce(ce),
                    .adc_a_i(adc_i[(2*p)*ADC_BITS +: ADC_BITS]),
                    .adc_b_i(adc_i[(2*p+1)*ADC_BITS +: ADC_BITS]),
                    .rx_sign_i(rx_sign_i), .m_i(m_i),
                    .ps_valid_o(p_valid[p]), .ps_row_o(p_row[p*ROW_W +: ROW_W]),
                    .ps_tag_o(p_tag[p*(MC_W+2) +: MC_W+2]),
                    .ps_ar_o(p_split[(4*p)*MW +: MW]), .ps_ai_o(p_split[(4*p+1)*MW +: MW]),
                    .ps_br_o(p_split[(4*p+2)*MW +: MW]), .ps_bi_o(p_split[(4*p+3)*MW +: MW]),
                    .rd_row_i(row_q), .rd_data_o(cells[p*2*CW +: 2*CW]),   // {cell b, cell a}
                    .fft_ovf_o(p_ovf[p]));
            end
            assign push_v      = p_valid[0];
            assign push_row    = p_row[ROW_W-1:0];
            assign push_tag    = p_tag[MC_W+1:0];
            assign chk_v       = p_valid[0];
            assign chk_row     = p_row[ROW_W-1:0];
            assign seq_ovf     = 1'b0;
            assign fft_ovf_any = |p_ovf;
        end else begin : g_groups
            wire [NGRP-1:0]          g_valid, g_ovf, g_seq;
            wire [NGRP*GCH_W-1:0]    g_ch;
            wire [NGRP*ROW_W-1:0]    g_row;
            wire [NGRP*(MC_W+2)-1:0] g_tag;
            // the groups run in lockstep: group 0's valid, channel, row and tag stand for all
            /* verilator lint_off UNUSEDSIGNAL */
            wire [NGRP*GCH_W-1:0]    unused_ch  = g_ch;
            wire [NGRP*ROW_W-1:0]    unused_row = g_row;
            wire [NGRP*(MC_W+2)-1:0] unused_tag = g_tag;
            wire [NGRP-1:0]          unused_v   = g_valid;
            /* verilator lint_on UNUSEDSIGNAL */
            for (p = 0; p < NGRP; p = p + 1) begin : g_grp
                localparam NPG = (PAIRS - p * GC < GC) ? PAIRS - p * GC : GC;
                fmt_rx_group_front #(
                    .LOG2_N(LOG2_N), .ROWS(ROWS), .BIN_LO(BIN_LO), .BIN_STEP(BIN_STEP),
                    .ADC_BITS(ADC_BITS), .M_MAX(M_MAX), .FFT_OUT_W(W),
                    .G(GC), .NP(NPG), .ROW_W(ROW_W), .MC_W(MC_W),
                    .CH_W(GCH_W)
                ) u_front (
                    .clk(clk), .rst(rst), .ce(ce),
                    .adc_i(adc_i[(2*p*GC)*ADC_BITS +: 2*NPG*ADC_BITS]),
                    .rx_sign_i(rx_sign_i), .m_i(m_i),
                    .ps_valid_o(g_valid[p]), .ps_ch_o(g_ch[p*GCH_W +: GCH_W]),
                    .ps_row_o(g_row[p*ROW_W +: ROW_W]), .ps_tag_o(g_tag[p*(MC_W+2) +: MC_W+2]),
                    .rd_row_i(row_q), .rd_en_i(col_en[p*GC*2 +: NPG*2]),
                    .rd_data_o(cells[p*GC*2*CW +: NPG*2*CW]),
                    .fft_ovf_o(g_ovf[p]), .seq_ovf_o(g_seq[p]));
            end
            assign push_v      = g_valid[0] && (g_ch[GCH_W-1:0] == GCH_LAST);
            assign push_row    = g_row[ROW_W-1:0];
            assign push_tag    = g_tag[MC_W+1:0];
            assign chk_v       = g_valid[0] && (g_ch[GCH_W-1:0] == {GCH_W{1'b0}});
            assign chk_row     = g_row[ROW_W-1:0];
            assign seq_ovf     = |g_seq;
            assign fft_ovf_any = |g_ovf;
        end
    endgenerate

    // the stages after the split advance on every clk (POST_CLK = 1) or on ce
    wire post_ce = (POST_CLK != 0) ? 1'b1 : ce;

    // ---- row queue: {row, M, first, last} ----
    reg [ROW_W+MC_W+1:0] q_mem [0:QD-1];
    reg [ROW_W-1:0]      q_wr_q, q_rd_q;
    reg [ROW_W:0]        q_cnt_q;
    reg                  overrun_q;      // sticky: a row arrived with the queue full or
                                         // before its previous copy was read
    reg                  busy_q;         // the engine is feeding a row
    reg [G_W-1:0]        g_q;            // group being fed
    reg [MC_W+1:0]       etag_q;         // the row's {M, first, last}

    wire q_push = post_ce && push_v;
    wire q_full = (q_cnt_q == QD[ROW_W:0]);
    wire load   = post_ce && (q_cnt_q != {(ROW_W+1){1'b0}}) && (!busy_q || g_q == G_LAST);
    wire [ROW_W+MC_W+1:0] q_head = q_mem[q_rd_q];

    always @(posedge clk) begin
        if (q_push && !q_full) q_mem[q_wr_q] <= {push_row, push_tag};
    end

    always @(posedge clk) begin
        if (rst) begin
            q_wr_q    <= {ROW_W{1'b0}};
            q_rd_q    <= {ROW_W{1'b0}};
            q_cnt_q   <= {(ROW_W+1){1'b0}};
            overrun_q <= 1'b0;
            busy_q    <= 1'b0;
            g_q       <= {G_W{1'b0}};
        end else begin
            if (q_push && !q_full) q_wr_q <= q_wr_q + 1'b1;
            if ((q_push && q_full) || hazard || seq_ovf) overrun_q <= 1'b1;
            if (load)              q_rd_q <= q_rd_q + 1'b1;
            case ({q_push && !q_full, load})
                2'b10:   q_cnt_q <= q_cnt_q + 1'b1;
                2'b01:   q_cnt_q <= q_cnt_q - 1'b1;
                default: q_cnt_q <= q_cnt_q;
            endcase
            if (load) begin
                busy_q <= 1'b1;
                g_q    <= {G_W{1'b0}};
            end else if (post_ce && busy_q) begin
                if (g_q == G_LAST) busy_q <= 1'b0;
                else               g_q    <= g_q + 1'b1;
            end
        end
    end

    // data hazard: a row completes again (its result memories start to be rewritten)
    // while the previous window's copy is still queued or being fed
    reg  [ROWS-1:0]  pend_q;             // row queued or being fed
    wire             fed     = post_ce && busy_q && (g_q == G_LAST);   // row_q's last group read
    wire             hazard  = post_ce && chk_v && pend_q[chk_row] && !(fed && row_q == chk_row);
    always @(posedge clk) begin
        if (rst) begin
            pend_q <= {ROWS{1'b0}};
        end else begin
            if (fed)    pend_q[row_q]    <= 1'b0;
            if (q_push) pend_q[push_row] <= 1'b1;
        end
    end

    always @(posedge clk) begin
        if (load) begin
            row_q  <= q_head[ROW_W+MC_W+1 -: ROW_W];
            etag_q <= q_head[MC_W+1:0];
        end
    end

    // synthesis translate_off
    always @(posedge clk) begin
        if (!rst && ((q_push && q_full) || hazard))
            $display("%m: ERROR: row queue overrun at %0t (MAG_UNITS %0d too few for this ce rate)", $time, K);
    end
    // synthesis translate_on

    // ---- shared magnitude units: unit u takes cell g*K + u ----
    // the cell multiplexer (result memories' read data, group g) is registered in front
    // of the units, with the valid bit and the tag.  FFT_CH > 1: the result memories are
    // block RAM read at row_q into their read latch and output register, so the group,
    // the valid bit and the tag reach the multiplexer RD_LAT = 2 steps after the engine
    // named them; FFT_CH = 1: LUT RAM, read at once (RD_LAT = 0)
    localparam RD_LAT = (GC > 1) ? 2 : 0;
    wire            mx_v;                // the engine is feeding (delayed by RD_LAT)
    wire [TAGW-1:0] mx_tag;              // {row, g, M, first, last} (delayed by RD_LAT)
    genvar cc;
    generate
        if (RD_LAT > 0) begin : g_rd_dly
            // rv1 / rt1: the step between the read latch and the output register; oh1_q:
            // one-hot of that step's group: column c's half of its pair's output register
            // loads only in its group's step (else it clears), so the cell "multiplexer"
            // is an OR of the P cells of a unit
            reg             rv1_q, rv2_q;
            reg [TAGW-1:0]  rt1_q, rt2_q;
            reg [P-1:0]     oh1_q;
            integer gi;
            always @(posedge clk) begin
                if (rst) begin
                    rv1_q <= 1'b0;
                    rv2_q <= 1'b0;
                    oh1_q <= {P{1'b0}};
                end else if (post_ce) begin
                    rv1_q <= busy_q;
                    rv2_q <= rv1_q;
                    for (gi = 0; gi < P; gi = gi + 1)
                        oh1_q[gi] <= busy_q && (g_q == gi[G_W-1:0]);
                end
            end
            always @(posedge clk) begin
                if (post_ce) begin
                    rt1_q <= {row_q, g_q, etag_q};
                    rt2_q <= rt1_q;
                end
            end
            for (cc = 0; cc < COLS; cc = cc + 1) begin : g_col_en
                assign col_en[cc] = oh1_q[cc / K];
            end
            assign mx_v   = rv2_q;
            assign mx_tag = rt2_q;
        end else begin : g_rd_now
            assign col_en = {COLS{1'b0}};   // LUT-RAM result memories: no load enables
            /* verilator lint_off UNUSEDSIGNAL */
            wire unused_col_en = &{1'b0, col_en};
            /* verilator lint_on UNUSEDSIGNAL */
            assign mx_v   = busy_q;
            assign mx_tag = {row_q, g_q, etag_q};
        end
    endgenerate
    wire [K*MAGW-1:0] mags;
    wire            mg_valid;
    wire [TAGW-1:0] mg_tag;
    reg             sel_v_q;
    reg [TAGW-1:0]  sel_tag_q;
    always @(posedge clk) begin
        if (rst)
            sel_v_q <= 1'b0;
        else if (post_ce)
            sel_v_q <= mx_v;
    end
    always @(posedge clk) begin
        if (post_ce) sel_tag_q <= mx_tag;
    end
    genvar u;
    generate
        for (u = 0; u < K; u = u + 1) begin : g_unit
            // the P cells of unit u side by side, group g at [g*CW +: CW]
            wire [P*CW-1:0] lane;
            genvar gl;
            for (gl = 0; gl < P; gl = gl + 1) begin : g_lane
                assign lane[gl*CW +: CW] = cells[(gl*K+u)*CW +: CW];
            end
            reg [CW-1:0] sel_q;
            if (RD_LAT > 0) begin : g_or
                // only the cell of this step is non-zero (col_en): OR the P cells
                reg [CW-1:0] any;
                integer go;
                always @* begin
                    any = {CW{1'b0}};
                    for (go = 0; go < P; go = go + 1)
                        any = any | lane[go*CW +: CW];
                end
                always @(posedge clk) begin
                    if (post_ce) sel_q <= any;
                end
            end else begin : g_mux
                wire [G_W-1:0] mx_g = mx_tag[MC_W+2 +: G_W];
                always @(posedge clk) begin
                    if (post_ce) sel_q <= lane[mx_g*CW +: CW];
                end
            end
            if (u == 0) begin : g_lead
                fmt_magnitude #(.IN_W(MW), .ITER(MAG_ITER), .FRAC(MAG_FRAC), .TAG_W(TAGW)) u_mag (
                    .clk(clk), .rst(rst), .ce(post_ce), .in_valid_i(sel_v_q),
                    .in_re_i(sel_q[MW-1:0]), .in_im_i(sel_q[CW-1:MW]),
                    .in_tag_i(sel_tag_q),
                    .out_valid_o(mg_valid), .out_mag_o(mags[u*MAGW +: MAGW]), .out_tag_o(mg_tag));
            end else begin : g_follow
                // runs in lockstep with unit 0: its valid and tag are unit 0's
                /* verilator lint_off UNUSEDSIGNAL */
                wire unused_v, unused_t;
                /* verilator lint_on UNUSEDSIGNAL */
                fmt_magnitude #(.IN_W(MW), .ITER(MAG_ITER), .FRAC(MAG_FRAC), .TAG_W(1)) u_mag (
                    .clk(clk), .rst(rst), .ce(post_ce), .in_valid_i(sel_v_q),
                    .in_re_i(sel_q[MW-1:0]), .in_im_i(sel_q[CW-1:MW]), .in_tag_i(1'b0),
                    .out_valid_o(unused_v), .out_mag_o(mags[u*MAGW +: MAGW]), .out_tag_o(unused_t));
            end
        end
    endgenerate

    // ---- accumulator: one memory for all cells, address {row, g} ----
    // stage A: read the running sums (block RAM, synchronous read), hold the magnitudes;
    // stage A2: the block-RAM output register, the reciprocal ROM read at the row's M
    // (from the stage-A tag); stage B: the ROM's output register.
    // An address is read and written once per window (no read-after-write hazard).
    reg [K*SUM_W-1:0] acc_mem [0:(1<<AW)-1];
    reg [K*SUM_W-1:0] acc_rd_q, acc_rd2_q;
    reg [K*MAGW-1:0]  a_mag_q, a2_mag_q;
    reg [TAGW-1:0]    a_tag_q, a2_tag_q;
    reg               a_valid_q, a2_valid_q;
    wire [AW-1:0]     mg_addr = mg_tag[TAGW-1 -: AW];
    // the reciprocal ROM (rx_fixed.recip_rom; 256 words whatever M_MAX, MC_W <= 8), read
    // with the row's M beside the sums
    // in block RAM: rom_q is its read latch, rom2_q its output register (the LUT form
    // was a 9-level xc5v path from the tag's shift register)
    (* rom_style = "block", ram_style = "block" *) reg [RW-1:0] recip_rom [0:255];
    reg [RW-1:0]      rom_q, rom2_q;
    reg  [7:0]        a_m8;              // the row's M as an 8-bit ROM address
    always @* begin
        a_m8 = 8'd0;
        a_m8[MC_W-1:0] = a_tag_q[MC_W+1:2];
    end
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, "fmt_recip.hex"}, recip_rom);
`else
        $readmemh("fmt_recip.hex", recip_rom);
`endif
    end

    always @(posedge clk) begin
        if (post_ce) begin
            acc_rd_q  <= acc_mem[mg_addr];
            rom_q     <= recip_rom[a_m8];    // one step later: from the registered tag
            a_mag_q   <= mags;
            a_tag_q   <= mg_tag;
            acc_rd2_q <= acc_rd_q;
            a2_mag_q  <= a_mag_q;
            a2_tag_q  <= a_tag_q;
        end
    end

    // stage B: sum = first ? mag : sum + mag (exact), written back; only the last
    // window's sums go on.
    wire [AW-1:0]   a_addr  = a2_tag_q[TAGW-1 -: AW];
    wire            a_first = a2_tag_q[1];
    wire            a_last  = a2_tag_q[0];
    reg [K*SUM_W-1:0] sum_d;
    integer l;
    always @* begin
        for (l = 0; l < K; l = l + 1)
            sum_d[l*SUM_W +: SUM_W] = (a_first ? {SUM_W{1'b0}} : acc_rd2_q[l*SUM_W +: SUM_W])
                                    + {{MC_W{1'b0}}, a2_mag_q[l*MAGW +: MAGW]};
    end

    always @(posedge clk) begin
        if (post_ce && a2_valid_q) acc_mem[a_addr] <= sum_d;
    end

    localparam [RW:0] RADD = (42'd1 << (TR - T)) - 42'd1;
    // only bits TR-T .. TR of the rounded entry are R (R <= 2^T)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [RW:0]     r_round = {1'b0, rom2_q} + RADD;
    /* verilator lint_on UNUSEDSIGNAL */

    reg [K*SUM_W-1:0] b_sum_q;
    // {first, last} are spent at stage B (b_valid_q carries "last")
    /* verilator lint_off UNUSEDSIGNAL */
    reg [TAGW-1:0]    b_tag_q;
    /* verilator lint_on UNUSEDSIGNAL */
    reg               b_valid_q;
    always @(posedge clk) begin
        if (post_ce) begin
            b_sum_q <= sum_d;
            b_tag_q <= a2_tag_q;
            rom2_q  <= rom_q;
        end
    end

    // stage C1: t = sum + M 2^MAG_FRAC (the rounding half of 2M 2^MAG_FRAC), R =
    // ceil(entry / 2^(TR-T)) =
    // ceil(2^(T+l) / M), l = ceil(log2 M)
    wire [MC_W-1:0] b_m     = b_tag_q[MC_W+1:2];
    reg  [LW-1:0]   l_d;
    reg  [8:0]      m_ext;
    integer i;
    always @* begin
        m_ext = {{(9-MC_W){1'b0}}, b_m};
        l_d   = {LW{1'b0}};
        for (i = 0; i < 8; i = i + 1)
            if (m_ext > (9'd1 << i)) l_d = i[LW-1:0] + 1'b1;
    end
    reg [K*T-1:0]         c1_t_q;
    reg [T:0]             c1_r_q;
    reg [LW-1:0]          c1_l_q;
    reg [ROW_W+G_W-1:0]   c1_rg_q;
    reg                   c1_valid_q;
    always @(posedge clk) begin
        if (post_ce) begin
            for (l = 0; l < K; l = l + 1)
                c1_t_q[l*T +: T] <= {1'b0, b_sum_q[l*SUM_W +: SUM_W]}
                                  + ({{(T-MC_W){1'b0}}, b_m} << MAG_FRAC);
            c1_r_q  <= r_round[TR-T +: T+1];
            c1_l_q  <= l_d;
            c1_rg_q <= b_tag_q[TAGW-1 -: ROW_W+G_W];
        end
    end

    // stage C2: the products t R (exact, 2T + 1 bits) as four 17 x 17-bit partial
    // products (one multiplier each, operands and products registered): t = th 2^17 +
    // tl, R = Rh 2^17 + Rl; C2A the products, C2B {hh, ll} (no overlap) and the middle
    // sum hl + lh, C2C t R = {hh, ll} + (hl + lh) 2^17
    localparam HS = 17;                                      // partial operand width
    wire [2*HS-1:0] r34 = {{(2*HS-T-1){1'b0}}, c1_r_q};
    reg  [K*PW-1:0]       c2_p_q;
    reg  [LW-1:0]         c2a_l_q, c2b_l_q, c2_l_q;
    reg  [ROW_W+G_W-1:0]  c2a_rg_q, c2b_rg_q, c2_rg_q;
    reg                   c2a_valid_q, c2b_valid_q, c2_valid_q;
    genvar ln;
    generate
        for (ln = 0; ln < K; ln = ln + 1) begin : g_recip
            wire [2*HS-1:0] t34 = {{(2*HS-T){1'b0}}, c1_t_q[ln*T +: T]};
            reg  [2*HS-1:0] ll_q, lh_q, hl_q, hh_q;
            reg  [4*HS-1:0] hhll_q;
            reg  [2*HS:0]   mid_q;
            // t R < 2^PW: the top bits of the 4 HS + 2-bit sum are zero
            /* verilator lint_off UNUSEDSIGNAL */
            wire [4*HS+1:0] psum = {2'b00, hhll_q} + ({{(2*HS+1){1'b0}}, mid_q} << HS);
            /* verilator lint_on UNUSEDSIGNAL */
            always @(posedge clk) begin
                if (post_ce) begin
                    ll_q   <= t34[HS-1:0]    * r34[HS-1:0];
                    lh_q   <= t34[HS-1:0]    * r34[2*HS-1:HS];
                    hl_q   <= t34[2*HS-1:HS] * r34[HS-1:0];
                    hh_q   <= t34[2*HS-1:HS] * r34[2*HS-1:HS];
                    hhll_q <= {hh_q, ll_q};
                    mid_q  <= {1'b0, lh_q} + {1'b0, hl_q};
                    c2_p_q[ln*PW +: PW] <= psum[PW-1:0];
                end
            end
        end
    endgenerate
    always @(posedge clk) begin
        if (post_ce) begin
            c2a_l_q  <= c1_l_q;   c2b_l_q  <= c2a_l_q;   c2_l_q  <= c2b_l_q;
            c2a_rg_q <= c1_rg_q;  c2b_rg_q <= c2a_rg_q;  c2_rg_q <= c2b_rg_q;
        end
    end
    generate
        if (T + 1 > 2 * HS) begin : g_check_t
            // t R needs operands of at most 2 x 17 bits
            fmt_rx_array_T_too_wide u_bad_t ();
        end
    endgenerate

    // stage C3: cell = (t R) >> (T + 1 + MAG_FRAC + l) = floor((sum + M F) / 2MF), saturated
    reg [K*HM_W-1:0] cell_d;
    reg              clip_d;
    reg [QW-1:0]     scaled;
    always @* begin
        clip_d = 1'b0;
        for (l = 0; l < K; l = l + 1) begin
            scaled = c2_p_q[l*PW + T + 1 + MAG_FRAC +: QW] >> c2_l_q;
            if (scaled > {{(QW-HM_W){1'b0}}, {HM_W{1'b1}}}) begin
                cell_d[l*HM_W +: HM_W] = {HM_W{1'b1}};
                clip_d = 1'b1;
            end else begin
                cell_d[l*HM_W +: HM_W] = scaled[HM_W-1:0];
            end
        end
    end

    reg [K*HM_W-1:0] c_cells_q;
    reg [ROW_W-1:0]  c_row_q;
    reg [G_W-1:0]    c_g_q;
    reg              c_valid_q;
    reg              sat_q;
    always @(posedge clk) begin
        if (post_ce) begin
            c_cells_q <= cell_d;
            c_row_q   <= c2_rg_q[ROW_W+G_W-1 -: ROW_W];
            c_g_q     <= c2_rg_q[G_W-1:0];
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            a_valid_q  <= 1'b0;
            a2_valid_q <= 1'b0;
            b_valid_q  <= 1'b0;
            c2a_valid_q <= 1'b0;
            c2b_valid_q <= 1'b0;
            c1_valid_q <= 1'b0;
            c2_valid_q <= 1'b0;
            c_valid_q  <= 1'b0;
            sat_q      <= 1'b0;
        end else if (post_ce) begin
            a_valid_q  <= mg_valid;
            a2_valid_q <= a_valid_q;
            b_valid_q  <= a2_valid_q && a_last;
            c1_valid_q <= b_valid_q;
            c2a_valid_q <= c1_valid_q;
            c2b_valid_q <= c2a_valid_q;
            c2_valid_q <= c2b_valid_q;
            c_valid_q  <= c2_valid_q;
            if (c2_valid_q && clip_d) sat_q <= 1'b1;
        end
    end

    // stage D: the row register and the stream
    reg [P*K*HM_W-1:0] row_q_data;
    integer gg;
    always @(posedge clk) begin
        if (post_ce && c_valid_q) begin
            for (gg = 0; gg < P; gg = gg + 1)
                if (c_g_q == gg[G_W-1:0]) row_q_data[gg*K*HM_W +: K*HM_W] <= c_cells_q;
        end
    end
    assign hm_data_o = row_q_data[COLS*HM_W-1:0];
    generate
        if (P * K > COLS) begin : g_pad_out
            // the last group's cells beyond COLS are zero magnitudes of padding
            /* verilator lint_off UNUSEDSIGNAL */
            wire [(P*K-COLS)*HM_W-1:0] unused_pad = row_q_data[P*K*HM_W-1:COLS*HM_W];
            /* verilator lint_on UNUSEDSIGNAL */
        end
    endgenerate

    wire row_done = c_valid_q && (c_g_q == G_LAST);
    reg  eof_pend_q;   // the frame's last row has gone out, hm_eof_o follows
    always @(posedge clk) begin
        if (rst) begin
            eof_pend_q <= 1'b0;
            hm_valid_o <= 1'b0;
            hm_eof_o   <= 1'b0;
            hm_frame_o <= {FRAME_W{1'b0}};
        end else begin
            hm_valid_o <= 1'b0;
            hm_eof_o   <= 1'b0;
            if (post_ce) begin
                if (row_done) begin
                    hm_valid_o <= 1'b1;
                    if (c_row_q == LAST_ROW[ROW_W-1:0]) eof_pend_q <= 1'b1;
                end else if (eof_pend_q) begin
                    hm_eof_o   <= 1'b1;
                    eof_pend_q <= 1'b0;
                end
            end
            if (hm_eof_o) hm_frame_o <= hm_frame_o + 1'b1;
        end
    end

    always @(posedge clk) begin
        if (post_ce && row_done) hm_row_o <= c_row_q;
    end

    assign fft_ovf_o = fft_ovf_any;
    assign sat_o     = sat_q;
    assign overrun_o = overrun_q;

endmodule

`default_nettype wire
