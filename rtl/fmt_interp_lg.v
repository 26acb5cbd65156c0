// fmt_interp_lg -- pipelined base-2 logarithm of an unsigned integer (x > 0).
//
// lg_o = n * 2^12 + LOG_ROM[m] = {n, LOG_ROM[m]}, n = floor(log2 x) (position of the
// leading one), m = the 8 bits after the leading one (x is left-aligned first, so for
// n < 8 the missing bits are zeros), LOG_ROM[m] = round(4096 * log2(1 + (m + 0.5)/256))
// (12 fractional bits, < 4096).  Error |lg_o/4096 - log2 x| <= 0.0028 + 1/8192.
// x = 0 gives n = 0 and an undefined fraction (callers check x > 0).
// ROM rtl/fmt_interp_log.hex (256 x 12 bit, block RAM) is written by
// `python -m fmt.generate`.
// Latency: 3 clock cycles.  Twin: fmt.interp.lg_fixed.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_lg #(
    parameter X_W = 48                  // input width (>= 9)
) (
    input  wire                      clk,  // processing clock
    input  wire [X_W-1:0]            x_i,  // argument (unsigned, > 0)
    output wire [$clog2(X_W)+11:0]   lg_o  // log2(x) with 12 fractional bits, 3 cycles later
);
    localparam NB = $clog2(X_W);

    (* rom_style = "block" *)
    reg [11:0] rom [0:255];
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, "fmt_interp_log.hex"}, rom);
`else
        $readmemh("fmt_interp_log.hex", rom);
`endif
    end

    // The search in two steps of 8 bits (x zero-extended to XP = 8 * NG bits):
    // s1: the highest non-zero byte g and the 16-bit window x[8g+7 : 8g-8] (zeros
    //     below bit 0); s2: the leading one p of the window's top byte and the 8 bits
    //     after it, n = 8 g + p, and the ROM read (block RAM); s3: the read data registered.
    localparam NG = (X_W + 7) / 8;                  // bytes
    localparam GB = (NG > 1) ? $clog2(NG) : 1;      // byte index width
    localparam XP = 8 * NG;

    wire [XP+7:0] xw = {{(XP-X_W){1'b0}}, x_i, 8'd0};  // byte g of x at [8g+15 : 8g+8]
    reg  [GB-1:0] g_d;
    reg  [15:0]   w_d;
    integer i;
    always @(*) begin
        g_d = {GB{1'b0}};
        w_d = xw[15:0];
        for (i = 1; i < NG; i = i + 1)
            if (|xw[8*i+8 +: 8]) begin
                g_d = i[GB-1:0];
                w_d = xw[8*i +: 16];
            end
    end

    reg [GB-1:0] g_q;
    reg [15:0]   w_q;
    always @(posedge clk) begin
        g_q <= g_d;
        w_q <= w_d;
    end

    reg [2:0] p_d;
    reg [7:0] m_d;
    integer j;
    always @(*) begin
        p_d = 3'd0;
        m_d = w_q[7:0];
        for (j = 1; j < 8; j = j + 1)
            if (w_q[8+j]) begin
                p_d = j[2:0];
                m_d = w_q[7+j -: 8];
            end
    end
    /* verilator lint_off WIDTHEXPAND */ // n = 8 g + p fits NB bits (n < X_W)
    wire [NB-1:0] n_d = {g_q, p_d};
    /* verilator lint_on WIDTHEXPAND */

    // s2: the block RAM's read register (address m_d), s3: its output register
    reg [NB-1:0] n_q, n2_q;
    reg [11:0]   rd_q, f_q;
    always @(posedge clk) begin
        n_q  <= n_d;
        rd_q <= rom[m_d];
        n2_q <= n_q;
        f_q  <= rd_q;
    end
    assign lg_o = {n2_q, f_q};
endmodule
`default_nettype wire
