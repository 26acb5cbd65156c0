// fmt_rx_frame_win -- which window of a frame of M windows the FFT output is in, for the
// receive fronts (fmt_rx_pair_front, fmt_rx_group_front).
//
// win_i marks the first output slot of a new FFT window (combinational, from the FFT
// output).  A frame is M consecutive windows, M = m_i sampled at the frame's first window
// (0 is taken as 1, values above M_MAX are clamped); the first window after reset opens a
// frame.  Outputs, valid in the cycle of win_i and held until the next one: m_cur_o = M of
// the current frame, w_first_o / w_last_o = this window is the frame's first / last.
// The state advances on clk edges with en_i && win_i (en_i = the sample strobe where the
// FFT output is taken only on ce, or 1).  The first / last flags are registered with the
// state (the outputs are multiplexers after registers); the flag of the following
// window is recomputed on every clk, so two windows must start at least 2 clk apart.
`default_nettype none

module fmt_rx_frame_win #(
    parameter M_MAX = 255,                  // largest windows per frame M (1 .. 255)
    parameter MC_W  = $clog2(M_MAX + 1)     // width of m_i / m_cur_o
) (
    input  wire            clk,
    input  wire            rst,        // synchronous, active high
    input  wire            en_i,       // state enable (ce, or 1)
    input  wire            win_i,      // a new window starts at the FFT output
    input  wire [MC_W-1:0] m_i,        // windows per frame requested (0 = 1, > M_MAX = M_MAX)
    output wire [MC_W-1:0] m_cur_o,    // M of the current frame
    output wire            w_first_o,  // current window is the frame's first
    output wire            w_last_o    // current window is the frame's last
);

    localparam [MC_W-1:0] MMAX = M_MAX[MC_W-1:0];
    localparam [MC_W-1:0] MONE = 1;
    localparam [MC_W:0]   TWO  = 2;

    reg             started_q;
    reg [MC_W-1:0]  wcnt_q;                 // window index inside the frame, 0 .. M-1
    reg [MC_W-1:0]  m_q;                    // M of the current frame
    reg             first_q, last_q;        // the current window is the frame's first / last
    reg             nlast_q;                // the window after it would be the last (no wrap)
    wire [MC_W-1:0] m_lim;                  // m_i clamped to M_MAX
    generate
        if (M_MAX < (1 << MC_W) - 1) begin : g_clamp
            assign m_lim = (m_i > MMAX) ? MMAX : m_i;
        end else begin : g_noclamp
            assign m_lim = m_i;             // every MC_W-bit value is <= M_MAX
        end
    endgenerate
    wire [MC_W-1:0] m_in     = (m_lim == {MC_W{1'b0}}) ? MONE : m_lim;
    wire            m_in_one = (m_in == MONE);
    // the flags are registered with the state, so the outputs are a few multiplexers
    // after registers (nlast_q is recomputed every clk; windows are far apart)
    wire            wrap     = !started_q || last_q;
    wire [MC_W-1:0] w_cur    = win_i ? (wrap ? {MC_W{1'b0}} : wcnt_q + 1'b1) : wcnt_q;
    wire [MC_W-1:0] m_cur    = (win_i && wrap) ? m_in : m_q;

    assign m_cur_o   = m_cur;
    assign w_first_o = win_i ? wrap : first_q;
    assign w_last_o  = win_i ? (wrap ? m_in_one : nlast_q) : last_q;

    always @(posedge clk) begin
        if (rst) begin
            started_q <= 1'b0;
            wcnt_q    <= {MC_W{1'b0}};
            m_q       <= MONE;
            first_q   <= 1'b1;
            last_q    <= 1'b1;
        end else if (en_i && win_i) begin
            started_q <= 1'b1;
            wcnt_q    <= w_cur;
            m_q       <= m_cur;
            first_q   <= w_first_o;
            last_q    <= w_last_o;
        end
    end

    always @(posedge clk) begin
        nlast_q <= ({1'b0, wcnt_q} + TWO == {1'b0, m_q});
    end

endmodule

`default_nettype wire
