// fmt_div -- pipelined unsigned restoring divider, one result per clock.
//
// quot_o = floor(num_i / den_i) (low QW bits) and ovf_o = (num_i >= den_i * 2^QW),
// i.e. the quotient does not fit in QW bits (then quot_o is all ones).  den_i = 0
// always gives ovf_o = 1.  Stage s (s = 0..QW-1) decides quotient bit QW-1-s by a
// trial subtraction of den * 2^(QW-1-s) from the partial remainder.
// Latency: QW + 1 clock cycles from num_i/den_i/valid_i to quot_o/ovf_o/valid_o (one
// input register holding the overflow test, then one register per quotient bit).
// Twin: fmt.interp.div_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_div #(
    parameter NUM_W = 32,   // dividend width (unsigned)
    parameter DEN_W = 24,   // divisor width (unsigned)
    parameter QW    = 9     // quotient bits
) (
    input  wire             clk,      // processing clock
    input  wire             rst,      // synchronous active-high reset (clears valid)
    input  wire             valid_i,  // input strobe (only travels with the data)
    input  wire [NUM_W-1:0] num_i,    // dividend
    input  wire [DEN_W-1:0] den_i,    // divisor
    output wire             valid_o,  // valid_i delayed by QW + 1 cycles
    output wire [QW-1:0]    quot_o,   // floor(num / den), all ones on overflow
    output wire             ovf_o     // quotient >= 2^QW (or den = 0)
);
    // Remainder / shifted-divisor width: the divisor shifted by up to QW - 1 bits.
    localparam RW = ((NUM_W > DEN_W + QW) ? NUM_W : DEN_W + QW) + 1;

    reg [RW-1:0]    rem_q  [0:QW];
    reg [DEN_W-1:0] den_q  [0:QW];
    reg [QW-1:0]    quo_q  [0:QW];
    reg             ovf_q  [0:QW];
    reg             vld_q  [0:QW];

    // input stage: overflow test num >= den << QW
    wire [RW+QW-1:0] den_full = {{(RW+QW-DEN_W){1'b0}}, den_i} << QW;
    always @(posedge clk) begin
        rem_q[0] <= {{(RW-NUM_W){1'b0}}, num_i};
        den_q[0] <= den_i;
        quo_q[0] <= {QW{1'b0}};
        ovf_q[0] <= ({{(RW+QW-NUM_W){1'b0}}, num_i} >= den_full);
        if (rst) vld_q[0] <= 1'b0;
        else     vld_q[0] <= valid_i;
    end

    genvar s;
    generate
        for (s = 0; s < QW; s = s + 1) begin : g_stage
            localparam integer BIT = QW - 1 - s;   // quotient bit decided here
            wire [RW-1:0] trial = {{(RW-DEN_W){1'b0}}, den_q[s]} << BIT;
            wire          take  = (rem_q[s] >= trial);
            always @(posedge clk) begin
                rem_q[s+1] <= take ? (rem_q[s] - trial) : rem_q[s];
                den_q[s+1] <= den_q[s];
                quo_q[s+1] <= quo_q[s] | ({{(QW-1){1'b0}}, take} << BIT);
                ovf_q[s+1] <= ovf_q[s];
                if (rst) vld_q[s+1] <= 1'b0;
                else     vld_q[s+1] <= vld_q[s];
            end
        end
    endgenerate

    assign valid_o = vld_q[QW];
    assign ovf_o   = ovf_q[QW];
    assign quot_o  = ovf_q[QW] ? {QW{1'b1}} : quo_q[QW];
endmodule
`default_nettype wire
