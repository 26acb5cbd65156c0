// fmt_fft_bf -- one radix-2 single-path delay-feedback (SDF) butterfly stage of the
// radix-2^2 streaming FFT (fmt_fft_r22sdf), with the trivial -j rotation of the BF2II
// stages built in.
//
// Each incoming sample carries its position idx in the window (0..N-1).  With
// D = 2^LOG2_D and ctrl = idx[LOG2_D]:
//   ctrl = 0: the sample goes into the delay line; the stage outputs the delay line's
//             word (the differences of the previous block half).
//   ctrl = 1: a = delay line output (x[n]), b = this sample (x[n + D]);
//             output a + b, delay line <- a - b.
// MINUS_J = 1 (BF2II): when idx[LOG2_D+1] = 1 as well, b is first multiplied by -j
// (b' = b_im - j b_re): the second half of each 4D-block holds the BF2I differences.
// The stage is a pure delay of the sample order: the output element idx - D (mod N)
// leaves together with the input idx, registered.
//
// Fixed point: input DW bits signed, output DW + 1 bits, exact (no rounding, cannot
// overflow: |a +- b| < 2^DW; the -j swap only moves a component).
// Channels: with CH > 1 the input is CH interleaved streams (one element of each
// channel in turn, all CH of a sample index carrying the same idx); the delay line is
// D x CH steps long, so each element meets its own channel's partner (fmt_fft_r22sdf CH).
// Latency: D x CH + 1 ce-steps (delay line + output register): the element leaves one
// step after the input that pairs with it.  out_valid_o is 1 for the elements that came
// from valid inputs (the first valid input has idx 0 after reset).  nxt_idx_o
// (combinational) is the position the output takes on the next ce edge: the following
// twiddle reads its ROM with it one step ahead.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_fft_bf #(
    parameter LOG2_N  = `FMT_LOG2_N, // window length N = 2^LOG2_N
    parameter LOG2_D  = 0,           // delay D = 2^LOG2_D (D = N/2 for the first stage)
    parameter DW      = 13,          // input width (signed); output is DW + 1
    parameter MINUS_J = 0,           // 1: BF2II stage (-j on the second half of each 4D block)
    parameter RAM_MIN = 8,           // delay lines this long or longer use the RAM form
    parameter BRAM_MIN = 96,         // RAM rings this long or longer ask for block RAM
    parameter CH      = 1            // interleaved channels (delay line D x CH steps)
) (
    input  wire              clk,
    input  wire              rst,          // synchronous, active high
    input  wire              ce,           // sample strobe
    input  wire              in_valid_i,   // the input sample belongs to a window started after reset
    input  wire [LOG2_N-1:0] in_idx_i,     // its position in the window
    input  wire signed [DW-1:0] in_re_i,   // real part
    input  wire signed [DW-1:0] in_im_i,   // imaginary part
    output reg               out_valid_o,  // the output element is valid
    output reg  [LOG2_N-1:0] out_idx_o,    // its position in the window (block order)
    output wire [LOG2_N-1:0] nxt_idx_o,    // out_idx_o of the next ce step (in_idx_i - D; the twiddle ROM address)
    output reg  signed [DW:0] out_re_o,    // real part, DW + 1 bits
    output reg  signed [DW:0] out_im_o     // imaginary part, DW + 1 bits
);

    localparam D  = 1 << LOG2_D;
    localparam OW = DW + 1;

    wire ctrl = in_idx_i[LOG2_D];
    wire swap;
    generate
        if (MINUS_J != 0) begin : g_mj
            assign swap = ctrl & in_idx_i[LOG2_D + 1];
        end else begin : g_nomj
            assign swap = 1'b0;
        end
    endgenerate

    // delay line: {re, im}, OW bits each
    wire [2*OW-1:0] dl_out;
    wire signed [OW-1:0] a_re = dl_out[2*OW-1:OW];
    wire signed [OW-1:0] a_im = dl_out[OW-1:0];
    wire signed [OW-1:0] b_re = {in_re_i[DW-1], in_re_i};
    wire signed [OW-1:0] b_im = {in_im_i[DW-1], in_im_i};

    // b' = swap ? -j b : b = (b_im, -b_re).  Each sum/difference is one adder with its
    // operand selection, masking and carry-in folded into the LUT in front of the carry
    // chain (-x = ~x + 1):
    //   y  = ctrl ? a + b' : a      = a + (b' & ctrl)
    //   fb = ctrl ? a - b' : b      (the delay line input)
    wire [OW-1:0] mask   = {OW{ctrl}};
    wire [OW-1:0] bre_p  = swap ? b_im : b_re;            // Re b'
    wire [OW-1:0] bim_px = swap ? ~b_re : b_im;           // Im b' (minus the +1 when swap)
    wire [OW-1:0] bre_n  = ~bre_p;                        // -Re b' - 1
    wire [OW-1:0] bim_n  = swap ? b_re : ~b_im;           // -Im b' (minus the +1 when !swap)
    wire [OW-1:0] y_re   = a_re + (bre_p & mask);
    wire [OW-1:0] y_im   = a_im + (bim_px & mask) + {{(OW-1){1'b0}}, swap};
    wire [OW-1:0] dif_re = a_re + bre_n + {{(OW-1){1'b0}}, 1'b1};
    wire [OW-1:0] dif_im = a_im + bim_n + {{(OW-1){1'b0}}, ~swap};

    wire [2*OW-1:0] dl_in = ctrl ? {dif_re, dif_im} : {b_re, b_im};

    fmt_fft_delay #(.W(2 * OW), .DEPTH(D * CH), .RAM_MIN(RAM_MIN), .BRAM_MIN(BRAM_MIN)) u_delay (
        .clk(clk), .rst(rst), .ce(ce), .din_i(dl_in), .dout_o(dl_out));

    assign nxt_idx_o = in_idx_i - D[LOG2_N-1:0];

    // validity: the output element idx - D is valid once D valid samples came in
    reg  primed_q;
    wire idx_ge_d = (in_idx_i >> LOG2_D) != {LOG2_N{1'b0}};
    wire valid_d  = in_valid_i & (primed_q | idx_ge_d);

    always @(posedge clk) begin
        if (rst) begin
            primed_q    <= 1'b0;
            out_valid_o <= 1'b0;
            out_idx_o   <= {LOG2_N{1'b0}};
        end else if (ce) begin
            primed_q    <= primed_q | valid_d;
            out_valid_o <= valid_d;
            out_idx_o   <= nxt_idx_o;
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            out_re_o <= y_re;
            out_im_o <= y_im;
        end
    end

endmodule

`default_nettype wire
