// fmt_magnitude -- pipelined magnitude sqrt(re^2 + im^2) of a complex stream,
// one input per ce cycle, by CORDIC vectoring (shift-add only) plus one constant
// multiply for the CORDIC gain compensation.
//
// Algorithm (bit-exact twin: sim/fmt/rx_array.py magnitude_fixed):
//   x0 = |re| << GUARD, y0 = im << GUARD            (reflect into the right half plane)
//   for i = 0 .. ITER-1:                            (one pipeline stage each)
//     y >= 0: x += y >>> i, y -= x >>> i
//     y <  0: x -= y >>> i, y += x >>> i           (>>> = arithmetic shift, floor)
//   FRAC = 0: mag = (x * GAIN_C + 2^(GAIN_BITS+GUARD-1)) >> (GAIN_BITS+GUARD)
//             (round half up to an integer)
//   FRAC > 0: mag = (x * GAIN_C) >> (GAIN_BITS+GUARD-FRAC)   (|z| with FRAC fractional
//             bits, truncated: the user rounds once, e.g. fmt_rx_array's cell)
//   GAIN_C = round(2^GAIN_BITS / K), K = prod_i sqrt(1 + 2^-2i) (= 636751 for 20 bits,
//   relative gain error 1.9e-7).  Since 1/K > 1/2 the product is formed as
//   (x << (GAIN_BITS-1)) + x * (GAIN_C - 2^(GAIN_BITS-1)): a 17-bit constant multiply.
// Gain stages (after the last CORDIC register, which is the multiplier's operand
// register): M = the partial products x[17:0] * g and x[XW-1:18] * g (g = GAIN_C -
// 2^(GAIN_BITS-1); one 18-bit slice per product, so that each is one 18 x 18
// multiplier on ECP5 / one DSP48E with its product registered), beside them
// (x << (GAIN_BITS-1)) + rounding constant; P = the sum of the three, of which the
// output keeps bits [SH - FRAC +: IN_W + FRAC].  No multiplier output goes through LUTs
// before a register.
// Formats: re, im signed IN_W (integers); mag unsigned IN_W + FRAC bits, FRAC of them
// fractional (the largest magnitude, sqrt(2) * 2^(IN_W-1), is below 2^IN_W: no overflow
// is possible).
// Error (measured in sim/tests/test_rx_array.py over random full-scale inputs):
// |mag - exact| <= 1.1 LSB + 2e-7 |z|, mean bias below 0.15 LSB (ITER = 12, GUARD = 3).
// Internal width IW = IN_W + GUARD + 2 holds K * sqrt(2) * 2^(IN_W-1+GUARD) < 2^(IW-1).
// Latency: ITER + 3 ce cycles (input register, ITER stages, partial products, sum);
// a TAG_W-bit tag and the valid bit travel with the data.  Registers advance on ce.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_magnitude #(
    parameter IN_W      = 19,   // width of re/im (signed)
    parameter ITER      = 12,   // CORDIC iterations (angle residual <= atan(2^-(ITER-1)))
    parameter GUARD     = 3,    // extra fractional bits inside the CORDIC
    parameter GAIN_BITS = 20,   // fractional bits of the gain-compensation constant
    parameter GAIN_C    = 636751, // round(2^GAIN_BITS / K(ITER)), > 2^(GAIN_BITS-1); the model checks it
    parameter FRAC      = 0,    // fractional bits of the output: 0 = rounded half up to an
                                // integer; > 0 = truncated (0 .. GAIN_BITS + GUARD - 1)
    parameter TAG_W     = 8     // width of the side-band tag carried with each sample
) (
    input  wire                  clk,
    input  wire                  rst,       // synchronous, active high (clears valid)
    input  wire                  ce,        // sample strobe: the pipeline advances on ce
    input  wire                  in_valid_i, // a sample this ce cycle
    input  wire signed [IN_W-1:0] in_re_i,  // real part
    input  wire signed [IN_W-1:0] in_im_i,  // imaginary part
    input  wire [TAG_W-1:0]      in_tag_i,  // side band (row index, flags), delayed with the data
    output reg                   out_valid_o, // magnitude valid (ITER + 3 ce cycles later)
    output reg  [IN_W+FRAC-1:0]  out_mag_o, // unsigned magnitude, LSB = 2^-FRAC input LSB
    output reg  [TAG_W-1:0]      out_tag_o  // the sample's tag
);

    localparam IW  = IN_W + GUARD + 2;              // CORDIC register width (signed)
    localparam XW  = IW - 1;                        // final x: >= 0, below 2^(IW-1)
    localparam GLW = GAIN_BITS - 1;                 // g = GAIN_C - 2^(GAIN_BITS-1) < 2^GLW
    localparam ALW = (XW > 18) ? 18 : XW;           // x bits of the low partial product
    localparam AHW = XW - ALW;                      // x bits of the high one (0: none)
    localparam PW  = XW + GAIN_BITS + 1;            // x * GAIN_C + rounding < 2^PW
    localparam SH  = GAIN_BITS + GUARD;             // final right shift
    localparam NS  = ITER + 1;                      // stage registers 0..ITER

    // stage registers: index 0 = after the input register, i+1 = after iteration i
    reg signed [IW-1:0] x_q [0:NS-1];
    reg signed [IW-1:0] y_q [0:NS-1];
    reg [NS-1:0]        v_q;
    reg [TAG_W-1:0]     t_q [0:NS-1];

    // gain stage M: partial products and the shifted x plus the rounding constant
    reg [ALW+GLW-1:0]   pl_q;
    reg [PW-1:0]        c_q;
    reg                 mv_q;
    reg [TAG_W-1:0]     mt_q;

    wire signed [IW-1:0] re_ext = {{(IW-IN_W){in_re_i[IN_W-1]}}, in_re_i};
    wire signed [IW-1:0] im_ext = {{(IW-IN_W){in_im_i[IN_W-1]}}, in_im_i};
    wire signed [IW-1:0] re_abs = in_re_i[IN_W-1] ? -re_ext : re_ext;

    // GAIN_C lies in [2^(GAIN_BITS-1), 2^GAIN_BITS): g is GAIN_C without its top bit
    localparam [GAIN_BITS-1:0] GC = GAIN_C;
    wire [GLW-1:0] gain_lo = GC[GLW-1:0];
    // FRAC = 0: the half of the integer LSB; FRAC > 0: none (truncation)
    wire [PW-1:0]  round_w = (FRAC == 0) ? ({{(PW-1){1'b0}}, 1'b1} << (SH - 1)) : {PW{1'b0}};

    generate
        if (FRAC < 0 || FRAC >= SH) begin : g_check_frac
            // FRAC outside 0 .. GAIN_BITS + GUARD - 1: stop elaboration
            fmt_magnitude_FRAC_out_of_range u_bad_frac ();
        end
    endgenerate

    always @(posedge clk) begin
        if (rst) begin
            v_q <= {NS{1'b0}};
        end else if (ce) begin
            v_q <= {v_q[NS-2:0], in_valid_i};
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            x_q[0] <= re_abs <<< GUARD;
            y_q[0] <= im_ext <<< GUARD;
            t_q[0] <= in_tag_i;
        end
    end

    genvar i;
    generate
        for (i = 0; i < ITER; i = i + 1) begin : g_iter
            wire signed [IW-1:0] xs = x_q[i] >>> i;
            wire signed [IW-1:0] ys = y_q[i] >>> i;
            // one adder per word: y < 0 rotates counter-clockwise (x -= ys, y += xs),
            // y >= 0 clockwise (x += ys, y -= xs); a subtraction adds the inverted
            // operand plus a carry in (not an adder and a subtractor behind a mux)
            wire                 neg = y_q[i][IW-1];
            wire [IW-1:0]        x_n = x_q[i] + (ys ^ {IW{neg}}) + {{(IW-1){1'b0}}, neg};
            wire [IW-1:0]        y_n = y_q[i] + (xs ^ {IW{~neg}}) + {{(IW-1){1'b0}}, ~neg};
            always @(posedge clk) begin
                if (ce) begin
                    x_q[i+1] <= x_n;
                    y_q[i+1] <= y_n;
                    t_q[i+1] <= t_q[i];
                end
            end
        end
    endgenerate

    // x_q[ITER] >= 0 always (x0 >= 0 and x only grows in vectoring mode): its sign bit
    // is not used
    wire [XW-1:0] x_fin = x_q[NS-1][XW-1:0];

    always @(posedge clk) begin
        if (ce) begin
            pl_q <= x_fin[ALW-1:0] * gain_lo;
            c_q  <= ({{(PW-XW){1'b0}}, x_fin} << (GAIN_BITS - 1)) + round_w;
            mt_q <= t_q[NS-1];
        end
    end

    // the high partial product, already in place (<< ALW), or zero
    wire [PW-1:0] ph_sh;
    generate
        if (AHW > 0) begin : g_hi
            reg [AHW+GLW-1:0] ph_q;
            always @(posedge clk) begin
                if (ce) ph_q <= x_fin[XW-1:ALW] * gain_lo;
            end
            assign ph_sh = {{(PW-AHW-GLW){1'b0}}, ph_q} << ALW;
        end else begin : g_no_hi
            assign ph_sh = {PW{1'b0}};
        end
    endgenerate

    // gain stage P; the low SH - FRAC bits are the rounded-away (FRAC > 0: truncated)
    // fraction and the top bits are zero by range
    /* verilator lint_off UNUSEDSIGNAL */
    wire [PW-1:0] sum_w = {{(PW-ALW-GLW){1'b0}}, pl_q} + ph_sh + c_q;
    wire          unused_sign = x_q[NS-1][IW-1];
    /* verilator lint_on UNUSEDSIGNAL */

    always @(posedge clk) begin
        if (rst) begin
            mv_q        <= 1'b0;
            out_valid_o <= 1'b0;
        end else if (ce) begin
            mv_q        <= v_q[NS-1];
            out_valid_o <= mv_q;
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            out_mag_o <= sum_w[SH - FRAC +: IN_W + FRAC];
            out_tag_o <= mt_q;
        end
    end

endmodule

`default_nettype wire
