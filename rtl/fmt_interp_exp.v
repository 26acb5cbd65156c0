// fmt_interp_exp -- semi-axis from the log2 of its square: axis_o = 2^(L/2) in Q8.8.
//
// t = (L >>> 1) + 8 * 4096 (log2 of the axis in 1/256 cell, 12 fractional bits),
// k = t >>> 12, j = t[11:4]; m = EXP_ROM[j] = round(32768 * 2^((j + 0.5)/256)) (16 bit);
// axis = 0 for k < 0, m for k = 15, 0xFFFF (saturated) for k > 15, else
// (m + 2^(14-k)) >> (15 - k) (round half up).  Relative error <= 0.0014 + 1/2 LSB.
// ROM rtl/fmt_interp_exp.hex (256 x 16 bit) is written by `python -m fmt.generate`.
// Latency: 2 clock cycles.  Twin: fmt.interp.exp_axis_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_exp #(
    parameter LW = 22                   // width of L (signed)
) (
    input  wire                 clk,    // processing clock
    input  wire signed [LW-1:0] l_i,    // log2(axis^2 in cells^2), 12 fractional bits
    output reg         [15:0]   axis_o  // semi-axis, cells Q8.8, 2 cycles later
);
    reg [15:0] rom [0:255];
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, "fmt_interp_exp.hex"}, rom);
`else
        $readmemh("fmt_interp_exp.hex", rom);
`endif
    end

    /* verilator lint_off UNUSEDSIGNAL */ // t[3:0]: below the ROM's resolution (truncated)
    wire signed [LW-1:0] t = (l_i >>> 1) + (8 <<< 12);
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [LW-13:0] k = t[LW-1:12];

    reg signed [LW-13:0] k_q;
    reg        [15:0]    m_q;
    always @(posedge clk) begin
        k_q <= k;
        m_q <= rom[t[11:4]];
    end

    // round half up: (m + 2^(14-k)) >> (15-k) for 0 <= k <= 14 (fits 16 bits: m < 2^16)
    wire [3:0]  kk  = k_q[3:0];
    wire [16:0] sum = {1'b0, m_q} + ((k_q >= 0 && k_q < 15) ? (17'd1 << (4'd14 - kk)) : 17'd0);
    /* verilator lint_off UNUSEDSIGNAL */ // shr[16] is 0 for every shift >= 1 used below
    wire [16:0] shr = sum >> (4'd15 - kk);
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        if (k_q < 0)
            axis_o <= 16'd0;
        else if (k_q > 15)
            axis_o <= 16'hFFFF;
        else if (k_q == 15)
            axis_o <= m_q;
        else
            axis_o <= shr[15:0];
    end
endmodule
`default_nettype wire
