// fmt_tracker_vel -- one axis of the tracker's velocity / prediction update
// (combinational, used by fmt_tracker for the pair matched this cycle).
//
//   e     = (meas << VF) - p                (prediction error, P_W + 1 bits signed)
//   v_new = clamp(v + (e >>> shift), -vmax, +vmax)   (arithmetic shift = floor)
//   p_new = (meas << VF) + v_new            (prediction for the next frame)
// Twin: sim/fmt/tracker.py (Tracker.step, "update matched slots").
// The clamp is the max-speed setting (by design, not an overflow).
`default_nettype none

module fmt_tracker_vel #(
    parameter VF  = 12,           // extra fraction bits of p and v
    parameter V_W = 22,           // velocity width (signed)
    parameter P_W = 36            // prediction width (signed), >= 16 + VF + 2
) (
    input  wire [15:0]     meas_i,   // measured coordinate, unsigned Q8.8
    input  wire [P_W-1:0]  p_i,      // prediction, signed Q.(8+VF)
    input  wire [V_W-1:0]  v_i,      // velocity, signed, 2^-(8+VF) cells/frame
    input  wire [3:0]      shift_i,  // filter gain 2^-shift
    input  wire [V_W-2:0]  vmax_i,   // clamp magnitude
    output reg  [V_W-1:0]  v_o,      // new velocity
    output wire [P_W-1:0]  p_o       // new prediction
);

    localparam E_W = P_W + 2;

    wire signed [E_W-1:0] m_ext = $signed({{(E_W-16-VF){1'b0}}, meas_i, {VF{1'b0}}});
    wire signed [E_W-1:0] e     = m_ext - $signed({{2{p_i[P_W-1]}}, p_i});
    wire signed [E_W-1:0] es    = e >>> shift_i;
    wire signed [E_W-1:0] sum   = es + $signed({{(E_W-V_W){v_i[V_W-1]}}, v_i});
    wire signed [E_W-1:0] vmax  = $signed({{(E_W-V_W+1){1'b0}}, vmax_i});

    always @* begin
        if (sum > vmax)
            v_o = vmax[V_W-1:0];
        else if (sum < -vmax)
            v_o = -vmax[V_W-1:0];
        else
            v_o = sum[V_W-1:0];
    end

    assign p_o = m_ext[P_W-1:0] + {{(P_W-V_W){v_o[V_W-1]}}, v_o};

endmodule

`default_nettype wire
