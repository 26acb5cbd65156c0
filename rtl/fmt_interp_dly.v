// fmt_interp_dly -- fixed delay line of N clock cycles (N = 0: a wire), W bits wide.
// RST = 1: synchronous reset clears every stage (for valid/strobe bits); RST = 0: plain
// data registers (no reset, so they map to SRL shift registers).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_dly #(
    parameter W   = 1,  // width
    parameter N   = 1,  // delay in cycles (>= 0)
    parameter RST = 0   // 1: reset clears the stages
) (
    input  wire         clk,  // processing clock
    input  wire         rst,  // synchronous active-high reset (used when RST = 1)
    input  wire [W-1:0] d_i,  // input
    output wire [W-1:0] q_o   // d_i delayed by N cycles
);
    generate
        if (N == 0) begin : g_wire
            assign q_o = d_i;
            /* verilator lint_off UNUSEDSIGNAL */ // no registers: clk and rst unused
            wire unused = clk ^ rst;
            /* verilator lint_on UNUSEDSIGNAL */
        end else begin : g_regs
            reg [W-1:0] sr [0:N-1];
            integer i;
            always @(posedge clk) begin
                if (RST != 0 && rst) begin
                    for (i = 0; i < N; i = i + 1) sr[i] <= {W{1'b0}};
                end else begin
                    sr[0] <= d_i;
                    for (i = 1; i < N; i = i + 1) sr[i] <= sr[i-1];
                end
            end
            assign q_o = sr[N-1];
            if (RST == 0) begin : g_nr
                /* verilator lint_off UNUSEDSIGNAL */ // data-only delay: rst unused
                wire unused = rst;
                /* verilator lint_on UNUSEDSIGNAL */
            end
        end
    endgenerate
endmodule
`default_nettype wire
