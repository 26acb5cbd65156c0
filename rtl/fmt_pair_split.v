// fmt_pair_split -- separates the spectra of two real columns a, b that share one
// complex FFT (z = a + j b), at the comb bins only.
//
// For comb bin k = BIN_LO + r * BIN_STEP (row r) and its mirror N - k:
//   2 A[k] = Z[k] + conj(Z[N-k])        = (Zr[k] + Zr[N-k]) + j (Zi[k] - Zi[N-k])
//   2 B[k] = (Z[k] - conj(Z[N-k])) / j  = (Zi[k] + Zi[N-k]) + j (Zr[N-k] - Zr[k])
// The outputs are 2A and 2B, EXACT (no rounding): the /2 is not done here but folded
// into the heat-map scaling of fmt_accum (HM_SHIFT includes it).  Width: W + 1 signed.
//
// The bins arrive in any order (bit-reversed from fmt_fft_r22sdf), one per ce cycle.
// Step 1 registers the bin's decode (comb bin k or mirror N-k, row); step 2 reads the
// held memory: the first of a pair to arrive is held in a ROWS-entry memory
// (distributed RAM, with a bit saying whether it was k or N-k); when its partner
// arrives, (2A, 2B) of row r are registered: they leave two ce cycles after the
// partner came in (latency 2 ce cycles; the memory and the held bits are read and
// written in step 2 only, so consecutive bins never see a stale entry).  A per-row
// "held" bit makes this order independent; reset clears it.  Twin: sim/fmt/rx_array.py pair_split_fixed.
// Channels (CH > 1): the input interleaves CH FFT streams in lockstep (fmt_fft_r22sdf
// CH, in_ch_i = its out_ch_o): every bin arrives for channel 0, 1, .., CH-1 in turn, all
// channels in the same bin order.  The held memory is per {channel, row} (CH x 2^ROW_W
// entries, LUT RAM); the held bits stay one per row, read by every channel and updated
// by channel CH-1 (the channels of a bin all see the state before that bin).  out_ch_o
// names the output's channel.  One split serves the CH column pairs of one
// time-multiplexed FFT engine.  HELD_BRAM = 1 (default for CH >= 3): the held memory is
// block RAM with a registered read (no LUT RAM, no read multiplexer): step 2 its read
// latch, step 3 its output register (every bin is written back there; the second of a
// pair writes a dead entry, its held bit is cleared), step 4 the sums: latency 4 ce
// cycles.  The same {channel, row} is read again only at the mirror bin, >= CH >= 3
// steps later, after the write.
// Requires BIN_LO >= 1 and BIN_LO + (ROWS-1)*BIN_STEP < N/2 (checked by params.py), so
// a bin and its mirror are never the same bin.  BIN_STEP that is not a power of two
// costs a constant divider on the bin index.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_pair_split #(
    parameter LOG2_N   = `FMT_LOG2_N,    // FFT size N = 2^LOG2_N
    parameter ROWS     = `FMT_ROWS,      // comb bins (rows)
    parameter BIN_LO   = `FMT_BIN_LO,    // bin of row 0
    parameter BIN_STEP = `FMT_BIN_STEP,  // bins between rows
    parameter W        = 18,             // FFT output width (signed)
    parameter TAG_W    = 4,              // side band carried from the second bin to the output
    parameter ROW_W    = (ROWS > 1) ? $clog2(ROWS) : 1, // row index width
    parameter CH       = 1,              // interleaved channels (column pairs)
    parameter CH_W     = (CH > 1) ? $clog2(CH) : 1,     // channel index width
    parameter HELD_BRAM = (CH >= 3) ? 1 : 0             // 1: the held memory in block RAM
                                                        // (registered read, LAT 4; needs CH >= 3)
) (
    input  wire                 clk,
    input  wire                 rst,       // synchronous, active high
    input  wire                 ce,        // sample strobe
    input  wire                 in_valid_i, // FFT output bin valid
    input  wire [LOG2_N-1:0]    in_bin_i,  // its bin index 0..N-1
    input  wire signed [W-1:0]  in_re_i,   // Z[bin] real
    input  wire signed [W-1:0]  in_im_i,   // Z[bin] imaginary
    input  wire [TAG_W-1:0]     in_tag_i,  // side band (taken with the second bin of a pair)
    input  wire [CH_W-1:0]      in_ch_i,   // channel of the input bin (CH > 1; unused when CH = 1)
    output reg                  out_valid_o, // one row's (2A, 2B) this ce cycle
    output reg  [ROW_W-1:0]     out_row_o, // row index r
    output reg  signed [W:0]    a_re_o,    // 2 Re A[k]
    output reg  signed [W:0]    a_im_o,    // 2 Im A[k]
    output reg  signed [W:0]    b_re_o,    // 2 Re B[k]
    output reg  signed [W:0]    b_im_o,    // 2 Im B[k]
    output reg  [TAG_W-1:0]     out_tag_o, // in_tag_i of the second bin
    output reg  [CH_W-1:0]      out_ch_o   // channel of the output row
);

    localparam N   = 1 << LOG2_N;
    localparam DW  = LOG2_N + 2;           // signed width for bin differences
    localparam SPAN = ROWS * BIN_STEP;

    // ---- decode: is in_bin_i a comb bin (k) or a mirror (N-k), and of which row ----
    localparam [31:0]          LO_I   = BIN_LO;
    localparam [31:0]          N_I    = N;
    localparam [31:0]          SPAN_I = SPAN;
    localparam [31:0]          STEP_I = BIN_STEP;
    localparam signed [DW-1:0] LO_S   = LO_I[DW-1:0];
    localparam signed [DW-1:0] N_S    = N_I[DW-1:0];
    localparam signed [DW-1:0] SPAN_S = SPAN_I[DW-1:0];
    localparam signed [DW-1:0] STEP_S = STEP_I[DW-1:0];
    localparam signed [DW-1:0] ZERO_S = 0;
    wire signed [DW-1:0] bin_s  = {2'b00, in_bin_i};
    wire signed [DW-1:0] d_k    = bin_s - LO_S;                   // k - BIN_LO
    wire signed [DW-1:0] d_m    = N_S - bin_s - LO_S;             // (N - bin) - BIN_LO
    wire                 hit_k  = (d_k >= ZERO_S) && (d_k < SPAN_S) && ((d_k % STEP_S) == ZERO_S);
    wire                 hit_m  = (d_m >= ZERO_S) && (d_m < SPAN_S) && ((d_m % STEP_S) == ZERO_S);
    // the quotients are < ROWS when they are used: only their low ROW_W bits matter
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [DW-1:0] r_k    = d_k / STEP_S;
    wire signed [DW-1:0] r_m    = d_m / STEP_S;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [ROW_W-1:0]     row_in = hit_m ? r_m[ROW_W-1:0] : r_k[ROW_W-1:0];

    // ---- step 1: decode register ----
    reg                 d_hit_q, d_m_q;     // a comb bin or its mirror; it is the mirror
    reg [ROW_W-1:0]     d_row_q;
    reg [CH_W-1:0]      d_ch_q;
    reg signed [W-1:0]  d_re_q, d_im_q;
    reg [TAG_W-1:0]     d_tag_q;

    always @(posedge clk) begin
        if (rst) begin
            d_hit_q <= 1'b0;
        end else if (ce) begin
            d_hit_q <= in_valid_i && (hit_k || hit_m);
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            d_m_q   <= hit_m;
            d_row_q <= row_in;
            d_ch_q  <= in_ch_i;
            d_re_q  <= in_re_i;
            d_im_q  <= in_im_i;
            d_tag_q <= in_tag_i;
        end
    end

    // ---- held first-of-pair memory, per {channel, row}; sums ----
    localparam AW = (CH > 1) ? CH_W + ROW_W : ROW_W;
    localparam MD = (CH > 1) ? (1 << AW) : ROWS;
    localparam integer CHM1 = CH - 1;
    localparam [CH_W-1:0] CH_LAST = CHM1[CH_W-1:0];
    wire [AW-1:0] d_addr;                  // held memory address {channel, row} of the decode register
    generate
        if (CH > 1) begin : g_ch
            assign d_addr = {d_ch_q, d_row_q};
        end else begin : g_one
            assign d_addr = d_row_q;
        end
    endgenerate

    // the step that pairs: its bin, the held entry of its {channel, row}
    wire                s_hit;             // a comb bin or its mirror
    wire                hit_q;             // it is the mirror (q = Z[N-k])
    wire [ROW_W-1:0]    row;
    wire [CH_W-1:0]     s_ch;
    wire signed [W-1:0] s_re, s_im;
    wire [TAG_W-1:0]    s_tag;
    wire [2*W:0]        rd;                // held entry {is_mirror, re, im}
    wire                second;            // the second arrival of a pair: the other member is held

    generate
        if (HELD_BRAM != 0 && CH < 3) begin : g_check_bram
            // the block-RAM form reads an entry again >= CH steps after writing it at step 3
            fmt_pair_split_HELD_BRAM_needs_CH_ge_3 u_bad ();
        end
    endgenerate

    generate
        if (HELD_BRAM != 0) begin : g_bram
            // block RAM, registered read: step 2 the read latch (address from the decode
            // register), step 3 the block-RAM output register, step 4 the sums.  Every
            // bin is written back at step 3 (the second of a pair too: it clears held,
            // so the entry is dead); the same {channel, row} is read again at the
            // mirror bin, >= CH >= 3 steps later, after that write
            (* ram_style = "block" *) reg [2*W:0] mem [0:MD-1];
            reg [2*W:0]         h_lat_q, h_out_q;
            reg                 e_hit_q, e_m_q, f_hit_q, f_m_q;
            reg [ROW_W-1:0]     e_row_q, f_row_q;
            reg [CH_W-1:0]      e_ch_q, f_ch_q;
            reg signed [W-1:0]  e_re_q, e_im_q, f_re_q, f_im_q;
            reg [TAG_W-1:0]     e_tag_q, f_tag_q;
            wire [AW-1:0]       e_addr;
            if (CH > 1) begin : g_ea
                assign e_addr = {e_ch_q, e_row_q};
            end else begin : g_ea1
                assign e_addr = e_row_q;
            end
            always @(posedge clk) begin
                if (ce) begin
                    h_lat_q <= mem[d_addr];
                    h_out_q <= h_lat_q;
                    if (e_hit_q) mem[e_addr] <= {e_m_q, e_re_q, e_im_q};
                end
            end
            always @(posedge clk) begin
                if (rst) begin
                    e_hit_q <= 1'b0;
                    f_hit_q <= 1'b0;
                end else if (ce) begin
                    e_hit_q <= d_hit_q;
                    f_hit_q <= e_hit_q;
                end
            end
            always @(posedge clk) begin
                if (ce) begin
                    e_m_q <= d_m_q;     f_m_q <= e_m_q;
                    e_row_q <= d_row_q; f_row_q <= e_row_q;
                    e_ch_q <= d_ch_q;   f_ch_q <= e_ch_q;
                    e_re_q <= d_re_q;   f_re_q <= e_re_q;
                    e_im_q <= d_im_q;   f_im_q <= e_im_q;
                    e_tag_q <= d_tag_q; f_tag_q <= e_tag_q;
                end
            end
            assign s_hit = f_hit_q;
            assign hit_q = f_m_q;
            assign row   = f_row_q;
            assign s_ch  = f_ch_q;
            assign s_re  = f_re_q;
            assign s_im  = f_im_q;
            assign s_tag = f_tag_q;
            assign rd    = h_out_q;
        end else begin : g_lutram
            // LUT RAM, read asynchronously in step 2; only a first arrival is written
            reg [2*W:0] mem [0:MD-1];
            always @(posedge clk) begin
                if (ce && d_hit_q && !second) begin
                    mem[d_addr] <= {d_m_q, d_re_q, d_im_q};
                end
            end
            assign s_hit = d_hit_q;
            assign hit_q = d_m_q;
            assign row   = d_row_q;
            assign s_ch  = d_ch_q;
            assign s_re  = d_re_q;
            assign s_im  = d_im_q;
            assign s_tag = d_tag_q;
            assign rd    = mem[d_addr];
        end
    endgenerate

    wire          upd = (CH > 1) ? (s_ch == CH_LAST) : 1'b1;   // the last channel of this bin: update held_q
    reg [ROWS-1:0] held_q;                 // per row, shared by the channels

    wire                held     = held_q[row];
    wire signed [W-1:0] h_re     = rd[2*W-1:W];
    wire signed [W-1:0] h_im     = rd[W-1:0];
    wire signed [W:0]   hx_re    = {h_re[W-1], h_re};
    wire signed [W:0]   hx_im    = {h_im[W-1], h_im};
    wire signed [W:0]   cx_re    = {s_re[W-1], s_re};
    wire signed [W:0]   cx_im    = {s_im[W-1], s_im};
    // p = Z[k], q = Z[N-k]: the current bin is q when it is the mirror
    wire signed [W:0]   p_re     = hit_q ? hx_re : cx_re;
    wire signed [W:0]   p_im     = hit_q ? hx_im : cx_im;
    wire signed [W:0]   q_re     = hit_q ? cx_re : hx_re;
    wire signed [W:0]   q_im     = hit_q ? cx_im : hx_im;

    assign              second   = held && (rd[2*W] != hit_q);

    always @(posedge clk) begin
        if (rst) begin
            held_q      <= {ROWS{1'b0}};
            out_valid_o <= 1'b0;
        end else if (ce) begin
            out_valid_o <= 1'b0;
            if (s_hit) begin
                // the second arrival must be the other member of the pair
                if (second) begin
                    if (upd) held_q[row] <= 1'b0;
                    out_valid_o <= 1'b1;
                end else if (upd) begin
                    held_q[row] <= 1'b1;   // first arrival (or a repeat: keep the newest)
                end
            end
        end
    end

    // the sums are symmetric in (held, current); the differences take their operands
    // through the mirror flag's swap
    always @(posedge clk) begin
        if (ce) begin
            out_row_o <= row;
            a_re_o    <= hx_re + cx_re;        // p_re + q_re
            b_re_o    <= hx_im + cx_im;        // p_im + q_im
            a_im_o    <= p_im - q_im;
            b_im_o    <= q_re - p_re;
            out_tag_o <= s_tag;
            out_ch_o  <= s_ch;
        end
    end

endmodule

`default_nettype wire
