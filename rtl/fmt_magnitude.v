// fmt_magnitude -- pipelined magnitude sqrt(re^2 + im^2) of a complex stream,
// one input per ce cycle, by CORDIC vectoring (shift-add only) plus one constant
// multiply for the CORDIC gain compensation.
//
// Algorithm (bit-exact twin: sim/fmt/rx_fixed.py magnitude_fixed):
//   x0 = |re| << GUARD, y0 = im << GUARD            (reflect into the right half plane)
//   for i = 0 .. ITER-1:                            (one pipeline stage each)
//     y >= 0: x += y >>> i, y -= x >>> i
//     y <  0: x -= y >>> i, y += x >>> i           (>>> = arithmetic shift, floor)
//   mag = (x * GAIN_C + 2^(GAIN_BITS+GUARD-1)) >> (GAIN_BITS+GUARD)   (round half up)
//   GAIN_C = round(2^GAIN_BITS / K), K = prod_i sqrt(1 + 2^-2i) (= 636751 for 20 bits,
//   relative gain error 1.9e-7).  Since 1/K > 1/2 the product is formed as
//   (x << (GAIN_BITS-1)) + x * (GAIN_C - 2^(GAIN_BITS-1)): a 17-bit constant multiply.
// Formats: re, im signed IN_W (integers); mag unsigned OUT_W = IN_W (the largest
// magnitude, sqrt(2) * 2^(IN_W-1), is below 2^IN_W: no overflow is possible).
// Error (measured in sim/tests/test_rx_fixed.py over random full-scale inputs):
// |mag - exact| <= 1.1 LSB + 2e-7 |z|, mean bias below 0.15 LSB (ITER = 12, GUARD = 3).
// Internal width IW = IN_W + GUARD + 2 holds K * sqrt(2) * 2^(IN_W-1+GUARD) < 2^(IW-1).
// Latency: ITER + 3 ce cycles (input register, ITER stages, product, rounding);
// a TAG_W-bit tag and the valid bit travel with the data.  Registers advance on ce.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_magnitude #(
    parameter IN_W      = 19,   // width of re/im (signed)
    parameter ITER      = 12,   // CORDIC iterations (angle residual <= atan(2^-(ITER-1)))
    parameter GUARD     = 3,    // extra fractional bits inside the CORDIC
    parameter GAIN_BITS = 20,   // fractional bits of the gain-compensation constant
    parameter GAIN_C    = 636751, // round(2^GAIN_BITS / K(ITER)), > 2^(GAIN_BITS-1); the model checks it
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
    output reg  [IN_W-1:0]       out_mag_o, // unsigned magnitude, same LSB as the input
    output reg  [TAG_W-1:0]      out_tag_o  // the sample's tag
);

    localparam IW  = IN_W + GUARD + 2;              // CORDIC register width (signed)
    localparam GW  = GAIN_BITS + 2;                 // gain constant width (unsigned value)
    localparam PW  = IW + GW;                       // product width
    localparam SH  = GAIN_BITS + GUARD;             // final right shift
    localparam NS  = ITER + 1;                      // stage registers 0..ITER

    // stage registers: index 0 = after the input register, i+1 = after iteration i
    reg signed [IW-1:0] x_q [0:NS-1];
    reg signed [IW-1:0] y_q [0:NS-1];
    reg [NS-1:0]        v_q;
    reg [TAG_W-1:0]     t_q [0:NS-1];

    reg [PW-1:0]        prod_q;
    reg                 pv_q;
    reg [TAG_W-1:0]     pt_q;

    wire signed [IW-1:0] re_ext = {{(IW-IN_W){in_re_i[IN_W-1]}}, in_re_i};
    wire signed [IW-1:0] im_ext = {{(IW-IN_W){in_im_i[IN_W-1]}}, in_im_i};
    wire signed [IW-1:0] re_abs = in_re_i[IN_W-1] ? -re_ext : re_ext;

    // the constant minus its top bit, as a PW-bit unsigned operand
    wire [PW-1:0] gain_lo = GAIN_C - (1 << (GAIN_BITS - 1));
    wire [PW-1:0] round_w = {{(PW-1){1'b0}}, 1'b1} << (SH - 1);

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
            always @(posedge clk) begin
                if (ce) begin
                    if (y_q[i][IW-1]) begin        // y < 0: rotate counter-clockwise
                        x_q[i+1] <= x_q[i] - ys;
                        y_q[i+1] <= y_q[i] + xs;
                    end else begin                 // y >= 0: rotate clockwise
                        x_q[i+1] <= x_q[i] + ys;
                        y_q[i+1] <= y_q[i] - xs;
                    end
                    t_q[i+1] <= t_q[i];
                end
            end
        end
    endgenerate

    // x_q[ITER] >= 0 always (x0 >= 0 and x only grows in vectoring mode)
    wire [PW-1:0] x_fin = {{(PW-IW){1'b0}}, x_q[NS-1]};
    // the low SH bits are the rounded-away fraction and the top bits are zero by range
    /* verilator lint_off UNUSEDSIGNAL */
    wire [PW-1:0] prod_rnd = prod_q + round_w;
    /* verilator lint_on UNUSEDSIGNAL */

    always @(posedge clk) begin
        if (rst) begin
            pv_q        <= 1'b0;
            out_valid_o <= 1'b0;
        end else if (ce) begin
            pv_q        <= v_q[NS-1];
            out_valid_o <= pv_q;
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            prod_q  <= (x_fin << (GAIN_BITS - 1)) + x_fin * gain_lo;
            pt_q    <= t_q[NS-1];
            out_mag_o <= prod_rnd[SH +: IN_W];
            out_tag_o <= pt_q;
        end
    end

endmodule

`default_nettype wire
