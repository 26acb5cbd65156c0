// fmt_fft_twiddle -- twiddle multiplier between the stage pairs of fmt_fft_r22sdf.
//
// Element idx of the window sits at i = idx mod M in its M-block (M = 2^LOG2_M); it is
// multiplied by W_M^e(i), e(i) = r(q) n, q = i div (M/4), n = i mod (M/4),
// r = (0, 2, 1, 3), W_M = exp(-j 2 pi / M).  The ROM holds {cos, -sin} of W_M^e(i) per i
// (TW_W bits each, scale 2^(TW_W-2), so +1 and -1 are exact), read from the hex file
// fmt_fft_twMMMM.hex that sim/fmt/fft_r22sdf.py generates (folder: the macro FMT_ROM_DIR
// when defined, e.g. -DFMT_ROM_DIR=\"/path/to/rtl/\", else the name alone, as fmt_dds_rom2).
//
// Arithmetic: four DW x TW_W products (one DSP48E each, DW <= 25), each truncated
// (floor, arithmetic shift) by T = SH - GUARD bits, then
//   re = (p_ac>>>T - p_bs>>>T + 2^(GUARD-1)) >>> GUARD   (round half up)
//   im = (p_as>>>T + p_bc>>>T + 2^(GUARD-1)) >>> GUARD
// i.e. the exact round-half-up of (a c - b s) / 2^SH up to +-2^-GUARD output LSB from the
// truncation (the two floors' biases cancel).  The result keeps its low OW bits; if the
// value did not fit, ovf_o (sticky) is set: the FFT's growth plan makes that impossible,
// so no saturation hardware is spent on it, but it is never silent.
// Latency: 4 ce-steps (ROM/data register, products, difference/sum, rounded output).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_fft_twiddle #(
    parameter LOG2_N = `FMT_LOG2_N,  // window length N = 2^LOG2_N
    parameter LOG2_M = `FMT_LOG2_N,  // block size M = 2^LOG2_M (8..1024)
    parameter DW     = 15,           // input width (signed), <= 25 for one DSP48E per product
    parameter OW     = 19,           // output width (signed)
    parameter TW_W   = 18,           // twiddle width (signed), scale 2^(TW_W-2)
    parameter SH     = 13,           // right shift after the products (>= 1)
    parameter GUARD  = 3             // product bits kept below the output LSB (>= 1)
) (
    input  wire              clk,
    input  wire              rst,          // synchronous, active high
    input  wire              ce,           // sample strobe
    input  wire              in_valid_i,   // input element valid
    input  wire [LOG2_N-1:0] in_idx_i,     // its position in the window
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

    reg [2*TW_W-1:0] rom [0:M-1];
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, TW_NAME}, rom);
`else
        $readmemh(TW_NAME, rom);
`endif
    end

    // step 1: twiddle and data registers
    reg [2*TW_W-1:0]    tw_q;
    reg signed [DW-1:0] a_q, b_q;
    // step 2: truncated products
    reg signed [QW-1:0] p_ac_q, p_bs_q, p_as_q, p_bc_q;
    // step 3: difference and sum
    reg signed [SW-1:0] s_re_q, s_im_q;
    reg [LOG2_N-1:0]    idx1_q, idx2_q, idx3_q;
    reg                 v1_q, v2_q, v3_q;

    wire signed [TW_W-1:0] tw_c = tw_q[2*TW_W-1:TW_W];
    wire signed [TW_W-1:0] tw_s = tw_q[TW_W-1:0];

    // the low T bits of each product are dropped (floor)
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [PW-1:0] m_ac = a_q * tw_c;
    wire signed [PW-1:0] m_bs = b_q * tw_s;
    wire signed [PW-1:0] m_as = a_q * tw_s;
    wire signed [PW-1:0] m_bc = b_q * tw_c;
    /* verilator lint_on UNUSEDSIGNAL */

    always @(posedge clk) begin
        if (ce) begin
            tw_q   <= rom[in_idx_i[LOG2_M-1:0]];
            a_q    <= in_re_i;
            b_q    <= in_im_i;
            p_ac_q <= m_ac[PW-1:T];
            p_bs_q <= m_bs[PW-1:T];
            p_as_q <= m_as[PW-1:T];
            p_bc_q <= m_bc[PW-1:T];
            s_re_q <= {p_ac_q[QW-1], p_ac_q} - {p_bs_q[QW-1], p_bs_q};
            s_im_q <= {p_as_q[QW-1], p_as_q} + {p_bc_q[QW-1], p_bc_q};
        end
    end

    // step 4: round half up ((s + 2^(G-1)) >>> G), keep OW bits, flag if it did not fit
    wire signed [SW-1:0] half = {{(SW-1){1'b0}}, 1'b1} <<< (G - 1);
    // the low G bits only carry the rounding
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [SW-1:0] rs_re = s_re_q + half;
    wire signed [SW-1:0] rs_im = s_im_q + half;
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [RW-1:0] r_re = rs_re[SW-1:G];
    wire signed [RW-1:0] r_im = rs_im[SW-1:G];
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
