// fmt_interp_cordic -- pipelined vectoring CORDIC: magnitude and angle of (u, v).
//
// Pre-rotation: when u < 0, (u, v) -> (-u, -v) and the angle starts at pi; then N
// iterations i = 0..N-1: if v >= 0 {u += v >>> i; v -= u >>> i; z += atan(2^-i)} else
// the opposite (arithmetic shifts truncate toward -inf; u and v update from the old
// values; each update is one adder, its operand inverted with a carry in to subtract).
// Outputs: mag_o = u_N ~ K_N * |(u, v)| (K_12 = 1.64676), ang_o = z mod 2^16 in units
// of 2 pi / 65536 (= atan2(v, u)).  Table atan(2^-i) in the same unit, rounded;
// the model (fmt.interp.CORDIC_ATAN) generates it and sim/tests/test_interp.py checks
// that this file holds the same numbers.
// Latency: N + 1 clock cycles.  Twin: fmt.interp.cordic_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_cordic #(
    parameter IW = 22,   // input width (signed)
    parameter N  = 12    // iterations (<= 12: the table holds 12 angles)
) (
    input  wire                 clk,      // processing clock
    input  wire                 rst,      // synchronous active-high reset (clears valid)
    input  wire                 valid_i,  // input strobe (travels with the data)
    input  wire signed [IW-1:0] u_i,      // x component
    input  wire signed [IW-1:0] v_i,      // y component
    output wire                 valid_o,  // valid_i delayed by N + 1 cycles
    output wire        [IW+1:0] mag_o,    // K_N * |(u, v)| (non-negative)
    output wire        [15:0]   ang_o     // atan2(v, u), unit 2 pi / 65536
);
    localparam W = IW + 2;   // |u| grows by K_N < 2, and -(-2^(IW-1)) needs one bit

    function [15:0] atan_tab;
        input integer i;
        begin
            atan_tab = (i == 0) ? 16'd8192 :
                       (i == 1) ? 16'd4836 :
                       (i == 2) ? 16'd2555 :
                       (i == 3) ? 16'd1297 :
                       (i == 4) ? 16'd651 :
                       (i == 5) ? 16'd326 :
                       (i == 6) ? 16'd163 :
                       (i == 7) ? 16'd81 :
                       (i == 8) ? 16'd41 :
                       (i == 9) ? 16'd20 :
                       (i == 10) ? 16'd10 :
                       (i == 11) ? 16'd5 :
                       16'd0;
        end
    endfunction

    reg signed [W-1:0] u_q   [0:N];
    reg signed [W-1:0] v_q   [0:N];
    reg        [15:0]  z_q   [0:N];
    reg                vld_q [0:N];

    wire signed [W-1:0] u_x = {{2{u_i[IW-1]}}, u_i};
    wire signed [W-1:0] v_x = {{2{v_i[IW-1]}}, v_i};

    always @(posedge clk) begin
        if (u_i[IW-1]) begin
            u_q[0] <= -u_x;
            v_q[0] <= -v_x;
            z_q[0] <= 16'h8000;
        end else begin
            u_q[0] <= u_x;
            v_q[0] <= v_x;
            z_q[0] <= 16'h0000;
        end
        if (rst) vld_q[0] <= 1'b0;
        else     vld_q[0] <= valid_i;
    end

    genvar s;
    generate
        for (s = 0; s < N; s = s + 1) begin : g_iter
            localparam [15:0] AT = atan_tab(s);
            wire signed [W-1:0] us = u_q[s] >>> s;
            wire signed [W-1:0] vs = v_q[s] >>> s;
            // one adder per word: the operand inverted (plus a carry in) subtracts
            wire                neg = v_q[s][W-1];
            wire [W-1:0]        u_n = u_q[s] + (vs ^ {W{neg}}) + {{(W-1){1'b0}}, neg};
            wire [W-1:0]        v_n = v_q[s] + (us ^ {W{~neg}}) + {{(W-1){1'b0}}, ~neg};
            wire [15:0]         z_n = z_q[s] + (AT ^ {16{neg}}) + {15'd0, neg};
            always @(posedge clk) begin
                u_q[s+1] <= u_n;
                v_q[s+1] <= v_n;
                z_q[s+1] <= z_n;
                if (rst) vld_q[s+1] <= 1'b0;
                else     vld_q[s+1] <= vld_q[s];
            end
        end
    endgenerate

    assign valid_o = vld_q[N];
    assign mag_o   = u_q[N];
    assign ang_o   = z_q[N];
endmodule
`default_nettype wire
