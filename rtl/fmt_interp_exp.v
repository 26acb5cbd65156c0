// fmt_interp_exp -- semi-axis from the log2 of its square: axis_o = 2^(L/2) in Q8.8.
//
// t = (L >>> 1) + 8 * 4096 (log2 of the axis in 1/256 cell, 12 fractional bits),
// k = t >>> 12, j = t[11:4]; m = EXP_ROM[j] = round(32768 * 2^((j + 0.5)/256)) (16 bit);
// axis = 0 for k < 0, m for k = 15, 0xFFFF (saturated) for k > 15, else
// (m + 2^(14-k)) >> (15 - k) (round half up), formed as ((m >> (14 - k)) + 1) >> 1
// (the same value).  Relative error <= 0.0014 + 1/2 LSB.
// ROM rtl/fmt_interp_exp.hex (256 x 16 bit, block RAM) is written by
// `python -m fmt.generate`.
// Stages: l_i is sampled by the block RAM's address register and by k's register (the
// caller passes its combinational L), then the read data and the decoded k are
// registered, then the axis.  Latency: 3 clock cycles.  Twin: fmt.interp.exp_axis_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_exp #(
    parameter LW = 22                   // width of L (signed)
) (
    input  wire                 clk,    // processing clock
    input  wire signed [LW-1:0] l_i,    // log2(axis^2 in cells^2), 12 fractional bits
    output reg         [15:0]   axis_o  // semi-axis, cells Q8.8, 3 cycles later
);
    (* rom_style = "block" *)
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

    // e1: block RAM read register, k
    reg signed [LW-13:0] k_q;
    reg        [15:0]    rd_q;
    always @(posedge clk) begin
        k_q  <= k;
        rd_q <= rom[t[11:4]];
    end

    // e2: read data (the block RAM's output register), k decoded
    reg [15:0] m_q;
    reg        neg_q, sat_q, top_q;
    reg [3:0]  sh_q;
    /* verilator lint_off UNUSEDSIGNAL */ // kk[4]: sh_q is used for 0 <= k <= 14 only
    wire [4:0] kk = 5'd14 - {1'b0, k_q[3:0]};
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        m_q   <= rd_q;
        neg_q <= (k_q < 0);
        sat_q <= (k_q > 15);
        top_q <= (k_q == 15);
        sh_q  <= kk[3:0];
    end

    // e3: round half up
    wire [15:0] q  = m_q >> sh_q;
    /* verilator lint_off UNUSEDSIGNAL */ // q1[0]: dropped by the final halving
    wire [16:0] q1 = {1'b0, q} + 17'd1;
    /* verilator lint_on UNUSEDSIGNAL */
    always @(posedge clk) begin
        if (neg_q)
            axis_o <= 16'd0;
        else if (sat_q)
            axis_o <= 16'hFFFF;
        else if (top_q)
            axis_o <= m_q;
        else
            axis_o <= q1[16:1];
    end
endmodule
`default_nettype wire
