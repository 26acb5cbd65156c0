// fmt_interp_div -- pipelined fraction divider, one result per clock:
// quot_o = floor(mag_i * 2^QW / den_i) when mag_i < den_i, else ovf_o = 1 and quot_o
// all ones (den_i = 0 always overflows).  The same results as fmt_div with
// num_i = {mag_i, QW zeros}.
// Non-restoring division: the partial remainder R (signed, |R| < den) starts at mag and
// each stage forms R' = 2R - den when R >= 0, else 2R + den, one adder whose operand is
// den inverted by the sign (no restoring multiplexer); the quotient bit is R' >= 0,
// the same bit as the restoring division's (R' is the restoring remainder, minus den
// when the bit is 0).
// Latency: QW + 1 clock cycles (an input register holding the overflow test, then one
// register per quotient bit).  Twin: fmt.interp.div_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_div #(
    parameter MAG_W = 42,   // dividend width (unsigned), the fraction's numerator
    parameter DEN_W = 42,   // divisor width (unsigned)
    parameter QW    = 9     // quotient bits (>= 2)
) (
    input  wire             clk,    // processing clock
    input  wire [MAG_W-1:0] mag_i,  // numerator
    input  wire [DEN_W-1:0] den_i,  // divisor
    output wire [QW-1:0]    quot_o, // floor(mag * 2^QW / den), all ones on overflow
    output wire             ovf_o   // mag >= den (the quotient needs more than QW bits)
);
    localparam RW = DEN_W + 1;                            // |R| < den
    localparam CW = (MAG_W > DEN_W) ? MAG_W : DEN_W;      // comparison width

    reg signed [RW-1:0] r_q   [0:QW];
    reg [DEN_W-1:0]     den_q [0:QW];
    reg [QW-1:0]        q_q   [0:QW];
    reg                 ovf_q [0:QW];

    wire [CW-1:0] mag_c = {{(CW-MAG_W){1'b0}}, mag_i};
    wire [CW-1:0] den_c = {{(CW-DEN_W){1'b0}}, den_i};
    /* verilator lint_off WIDTHTRUNC */ // on overflow R0 is truncated (result replaced)
    /* verilator lint_off WIDTHEXPAND */
    always @(posedge clk) begin
        r_q[0]   <= mag_c;
        den_q[0] <= den_i;
        q_q[0]   <= {QW{1'b0}};
        ovf_q[0] <= (mag_c >= den_c);
    end
    /* verilator lint_on WIDTHEXPAND */
    /* verilator lint_on WIDTHTRUNC */

    genvar s;
    generate
        for (s = 0; s < QW; s = s + 1) begin : g_stage
            wire          sub = ~r_q[s][RW-1];                  // R >= 0: subtract den
            wire [RW:0]   t   = {r_q[s], 1'b0};                 // 2R
            wire [RW:0]   dx  = {2'b00, den_q[s]} ^ {(RW+1){sub}};
            /* verilator lint_off UNUSEDSIGNAL */ // |R'| < den: the top bit is a copy
            wire [RW:0]   r_n = t + dx + {{RW{1'b0}}, sub};
            /* verilator lint_on UNUSEDSIGNAL */
            always @(posedge clk) begin
                r_q[s+1]   <= r_n[RW-1:0];
                q_q[s+1]   <= {q_q[s][QW-2:0], ~r_n[RW-1]};
                den_q[s+1] <= den_q[s];
                ovf_q[s+1] <= ovf_q[s];
            end
        end
    endgenerate

    assign ovf_o  = ovf_q[QW];
    assign quot_o = ovf_q[QW] ? {QW{1'b1}} : q_q[QW];
endmodule
`default_nettype wire
