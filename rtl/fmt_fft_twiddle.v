// fmt_fft_twiddle -- twiddle multiplier between the stage pairs of fmt_fft_r22sdf.
//
// Element idx of the window sits at i = idx mod M in its M-block (M = 2^LOG2_M); it is
// multiplied by W_M^e(i), e(i) = r(q) n, q = i div (M/4), n = i mod (M/4),
// r = (0, 2, 1, 3), W_M = exp(-j 2 pi / M).  The ROM holds {cos, -sin} of W_M^e(i) per i
// (TW_W bits each, scale 2^(TW_W-2), so +1 and -1 are exact), read from the hex file
// fmt_fft_twMMMM.hex that sim/fmt/fft_r22sdf.py generates (folder: the macro FMT_ROM_DIR
// when defined, e.g. -DFMT_ROM_DIR=\"/path/to/rtl/\", else the name alone, as fmt_dds_rom2).
// ROMs of M >= ROM_BRAM_MIN words are block RAM (rom_style; read latch + output register
// as below), smaller ones LUTs.
//
// Arithmetic: four DW x TW_W products (one multiplier each when DW <= MUL_W, else two:
// see g_split), each truncated
// (floor, arithmetic shift) by T = SH - GUARD bits, then
//   re = (p_ac>>>T - p_bs>>>T + 2^(GUARD-1)) >>> GUARD   (round half up)
//   im = (p_as>>>T + p_bc>>>T + 2^(GUARD-1)) >>> GUARD
// i.e. the exact round-half-up of (a c - b s) / 2^SH up to +-2^-GUARD output LSB from the
// truncation (the two floors' biases cancel).  The result keeps its low OW bits; if the
// value did not fit, ovf_o (sticky) is set: the FFT's growth plan makes that impossible,
// so no saturation hardware is spent on it, but it is never silent.
// Pipeline (ce-steps; element k is presented on step k): the ROM is read one step
// ahead, with nxt_idx_i = the position of the element of the NEXT ce step (fmt_fft_bf
// nxt_idx_o): step k-1 ROM read register (block-RAM read latch), step k ROM output
// register (block-RAM output register) and data registers (the multiplier operands),
// k+1 products (DSP48E M register), k+2 difference/sum, k+3 rounded output.
// Latency: 4 ce-steps from in_* to out_* (nxt_idx_i one step earlier).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_fft_twiddle #(
    parameter LOG2_N = `FMT_LOG2_N,  // window length N = 2^LOG2_N
    parameter LOG2_M = `FMT_LOG2_N,  // block size M = 2^LOG2_M (8..1024)
    parameter DW     = 15,           // input width (signed), <= 25 for one DSP48E per product
    parameter OW     = 19,           // output width (signed)
    parameter TW_W   = 18,           // twiddle width (signed), scale 2^(TW_W-2)
    parameter SH     = 13,           // right shift after the products (>= 1)
    parameter GUARD  = 3,            // product bits kept below the output LSB (>= 1)
    parameter MUL_W  = 18,           // widest data operand of one multiplier (ECP5
                                     // MULT18X18D; DSP48E takes 25): wider data is split
    parameter ROM_BRAM_MIN = 16      // ROMs of this many words or more in block RAM
) (
    input  wire              clk,
    input  wire              rst,          // synchronous, active high
    input  wire              ce,           // sample strobe
    input  wire              in_valid_i,   // input element valid
    input  wire [LOG2_N-1:0] in_idx_i,     // its position in the window
    input  wire [LOG2_N-1:0] nxt_idx_i,    // position of the element of the next ce step (ROM address)
    input  wire signed [DW-1:0] in_re_i,   // real part
    input  wire signed [DW-1:0] in_im_i,   // imaginary part
    output reg               out_valid_o,  // output element valid (4 steps later)
    output reg  [LOG2_N-1:0] out_idx_o,    // its position
    output reg  signed [OW-1:0] out_re_o,  // rotated real part, OW bits
    output reg  signed [OW-1:0] out_im_o,  // rotated imaginary part
    output reg               ovf_o         // sticky: a valid element did not fit OW bits
);

    localparam M  = 1 << LOG2_M;
    localparam PW = DW + TW_W;                        // product width
    localparam T  = (SH > GUARD) ? SH - GUARD : 0;    // product bits dropped (floor)
    localparam G  = SH - T;                           // bits rounded off at the end
    localparam QW = PW - T;                           // truncated product width
    localparam SW = QW + 1;                           // difference/sum width
    localparam RW = SW - G;                           // width after rounding

    // file name "fmt_fft_twMMMM.hex" (M as four decimal digits, ASCII '0' = 48)
    localparam [31:0] DIG3 = 48 + (M / 1000) % 10;
    localparam [31:0] DIG2 = 48 + (M / 100) % 10;
    localparam [31:0] DIG1 = 48 + (M / 10) % 10;
    localparam [31:0] DIG0 = 48 + M % 10;
    localparam [8*18-1:0] TW_NAME = {"fmt_fft_tw", DIG3[7:0], DIG2[7:0], DIG1[7:0], DIG0[7:0], ".hex"};

    // step 0: ROM read register (the next element's twiddle); step 1: ROM output
    // register and data registers (the multiplier operands)
    reg [2*TW_W-1:0]    tw_q, tw2_q;
    generate
        if (M >= ROM_BRAM_MIN) begin : g_rom_bram
            // block RAM (its read latch tw_q and output register tw2_q): no LUTs
            (* rom_style = "block", ram_style = "block" *) reg [2*TW_W-1:0] rom [0:M-1];
            initial begin
`ifdef FMT_ROM_DIR
                $readmemh({`FMT_ROM_DIR, TW_NAME}, rom);
`else
                $readmemh(TW_NAME, rom);
`endif
            end
            always @(posedge clk) begin
                if (ce) tw_q <= rom[nxt_idx_i[LOG2_M-1:0]];
            end
        end else begin : g_rom_lut
            reg [2*TW_W-1:0] rom [0:M-1];
            initial begin
`ifdef FMT_ROM_DIR
                $readmemh({`FMT_ROM_DIR, TW_NAME}, rom);
`else
                $readmemh(TW_NAME, rom);
`endif
            end
            always @(posedge clk) begin
                if (ce) tw_q <= rom[nxt_idx_i[LOG2_M-1:0]];
            end
        end
    endgenerate
    reg signed [DW-1:0] a_q, b_q;
    reg [LOG2_N-1:0]    idx1_q, idx2_q, idx3_q;
    reg                 v1_q, v2_q, v3_q;

    // only the low LOG2_M bits of nxt_idx_i address the ROM
    /* verilator lint_off UNUSEDSIGNAL */
    wire unused_nxt = &{1'b0, nxt_idx_i};
    /* verilator lint_on UNUSEDSIGNAL */

    wire signed [TW_W-1:0] tw_c = tw2_q[2*TW_W-1:TW_W];
    wire signed [TW_W-1:0] tw_s = tw2_q[TW_W-1:0];

    always @(posedge clk) begin
        if (ce) begin
            tw2_q <= tw_q;
            a_q   <= in_re_i;
            b_q   <= in_im_i;
        end
    end

    // steps 2 and 3: products (registered), difference and sum; step 4 rounds
    // (s + 2^(G-1)) >>> G = (s >>> G) + s[G-1] (the half as the adder's carry in).
    wire signed [RW-1:0] r_re, r_im;       // rounded, before the OW-bit range check

    generate
        if (DW <= MUL_W) begin : g_one
            // one multiplier per product; the low T bits of each product are dropped (floor)
            reg signed [QW-1:0] p_ac_q, p_bs_q, p_as_q, p_bc_q;
            reg signed [SW-1:0] s_re_q, s_im_q;
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [PW-1:0] m_ac = a_q * tw_c;
            wire signed [PW-1:0] m_bs = b_q * tw_s;
            wire signed [PW-1:0] m_as = a_q * tw_s;
            wire signed [PW-1:0] m_bc = b_q * tw_c;
            /* verilator lint_on UNUSEDSIGNAL */
            always @(posedge clk) begin
                if (ce) begin
                    p_ac_q <= m_ac[PW-1:T];
                    p_bs_q <= m_bs[PW-1:T];
                    p_as_q <= m_as[PW-1:T];
                    p_bc_q <= m_bc[PW-1:T];
                    s_re_q <= {p_ac_q[QW-1], p_ac_q} - {p_bs_q[QW-1], p_bs_q};
                    s_im_q <= {p_as_q[QW-1], p_as_q} + {p_bc_q[QW-1], p_bc_q};
                end
            end
            // the low G-1 bits only carry the rounding
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [SW-1:0] re_g = s_re_q >>> G;
            wire signed [SW-1:0] im_g = s_im_q >>> G;
            /* verilator lint_on UNUSEDSIGNAL */
            assign r_re = re_g[RW-1:0] + {{(RW-1){1'b0}}, s_re_q[G-1]};
            assign r_im = im_g[RW-1:0] + {{(RW-1){1'b0}}, s_im_q[G-1]};
        end else begin : g_split
            // data wider than one multiplier: a = ah 2^LW + al, al = the low LW bits
            // (unsigned), ah = the high HW bits (signed); x tw = (ah tw) 2^LW + al tw, two
            // multipliers per product, both registered.  T <= LW - G, so
            //   floor(a tw / 2^T) = (ah tw) 2^(LW-T) + floor(al tw / 2^T)
            // and the high part is a multiple of 2^G: only the low part is rounded,
            //   r = (dh 2^(LW-T-G)) + (dl >>> G) + dl[G-1]
            // with dh, dl the high and low differences (sums): one adder per step.
            localparam LW  = MUL_W - 1;                   // low part bits (unsigned)
            localparam HW  = DW - LW;                     // high part bits (signed)
            localparam PLW = LW + 1 + TW_W;               // low product width
            localparam PHW = HW + TW_W;                   // high product width
            localparam QLW = PLW - T;                     // truncated low product width
            localparam SH2 = LW - T - G;                  // shift of dh in the result
            reg signed [QLW-1:0] pl_ac_q, pl_bs_q, pl_as_q, pl_bc_q;
            reg signed [PHW-1:0] ph_ac_q, ph_bs_q, ph_as_q, ph_bc_q;
            reg signed [QLW:0]   dl_re_q, dl_im_q;
            reg signed [PHW:0]   dh_re_q, dh_im_q;
            wire signed [LW:0]   al = {1'b0, a_q[LW-1:0]};
            wire signed [LW:0]   bl = {1'b0, b_q[LW-1:0]};
            wire signed [HW-1:0] ah = a_q[DW-1:LW];
            wire signed [HW-1:0] bh = b_q[DW-1:LW];
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [PLW-1:0] ml_ac = al * tw_c;
            wire signed [PLW-1:0] ml_bs = bl * tw_s;
            wire signed [PLW-1:0] ml_as = al * tw_s;
            wire signed [PLW-1:0] ml_bc = bl * tw_c;
            /* verilator lint_on UNUSEDSIGNAL */
            always @(posedge clk) begin
                if (ce) begin
                    pl_ac_q <= ml_ac[PLW-1:T];
                    pl_bs_q <= ml_bs[PLW-1:T];
                    pl_as_q <= ml_as[PLW-1:T];
                    pl_bc_q <= ml_bc[PLW-1:T];
                    ph_ac_q <= ah * tw_c;
                    ph_bs_q <= bh * tw_s;
                    ph_as_q <= ah * tw_s;
                    ph_bc_q <= bh * tw_c;
                    dl_re_q <= {pl_ac_q[QLW-1], pl_ac_q} - {pl_bs_q[QLW-1], pl_bs_q};
                    dl_im_q <= {pl_as_q[QLW-1], pl_as_q} + {pl_bc_q[QLW-1], pl_bc_q};
                    dh_re_q <= {ph_ac_q[PHW-1], ph_ac_q} - {ph_bs_q[PHW-1], ph_bs_q};
                    dh_im_q <= {ph_as_q[PHW-1], ph_as_q} + {ph_bc_q[PHW-1], ph_bc_q};
                end
            end
            // RW-bit results (the same bits as the one-multiplier form, wrap included)
            /* verilator lint_off UNUSEDSIGNAL */
            wire signed [RW+SH2+PHW:0] hi_re = {{(RW+SH2){dh_re_q[PHW]}}, dh_re_q} <<< SH2;
            wire signed [RW+SH2+PHW:0] hi_im = {{(RW+SH2){dh_im_q[PHW]}}, dh_im_q} <<< SH2;
            wire signed [RW+QLW:0]     lo_re = {{RW{dl_re_q[QLW]}}, dl_re_q} >>> G;
            wire signed [RW+QLW:0]     lo_im = {{RW{dl_im_q[QLW]}}, dl_im_q} >>> G;
            /* verilator lint_on UNUSEDSIGNAL */
            assign r_re = hi_re[RW-1:0] + lo_re[RW-1:0] + {{(RW-1){1'b0}}, dl_re_q[G-1]};
            assign r_im = hi_im[RW-1:0] + lo_im[RW-1:0] + {{(RW-1){1'b0}}, dl_im_q[G-1]};
            // elaboration check: the split needs T <= LW - G
            if (SH2 < 0) begin : g_bad
                fmt_fft_twiddle_split_needs_T_le_LW_minus_G u_bad ();
            end
        end
    endgenerate

    wire                 big;

    generate
        if (RW > OW) begin : g_chk
            // fits when the bits above OW-1 all equal the sign bit
            assign big = (r_re[RW-1:OW-1] != {(RW-OW+1){r_re[RW-1]}})
                       | (r_im[RW-1:OW-1] != {(RW-OW+1){r_im[RW-1]}});
        end else begin : g_nochk
            assign big = 1'b0;
        end
    endgenerate

    always @(posedge clk) begin
        if (ce) begin
            out_re_o <= r_re[OW-1:0];
            out_im_o <= r_im[OW-1:0];
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            v1_q <= 1'b0; v2_q <= 1'b0; v3_q <= 1'b0; out_valid_o <= 1'b0;
            idx1_q <= {LOG2_N{1'b0}}; idx2_q <= {LOG2_N{1'b0}}; idx3_q <= {LOG2_N{1'b0}};
            out_idx_o <= {LOG2_N{1'b0}};
            ovf_o <= 1'b0;
        end else if (ce) begin
            v1_q <= in_valid_i;  v2_q <= v1_q;  v3_q <= v2_q;  out_valid_o <= v3_q;
            idx1_q <= in_idx_i;  idx2_q <= idx1_q;  idx3_q <= idx2_q;  out_idx_o <= idx3_q;
            if (v3_q && big)
                ovf_o <= 1'b1;
        end
    end

endmodule

`default_nettype wire
