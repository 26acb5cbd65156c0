// fmt_tracker_vel -- one axis of the tracker's slot update, a 3-stage pipeline.
//
// Used by fmt_tracker (x and y) for the operation whose slot record is read in stage E1
// (the inputs are the LUT-RAM read data of E1); the new p and v come out of the stage-E4
// registers, 3 cycles later, one operation per cycle, no stall:
//   move (typ 1):      e = (meas << VF) - p;   v' = clamp(v + (e >>> shift), +-vmax);
//                      p' = (meas << VF) + v'        (arithmetic shift = floor)
//   new  (typ 0):      p' = meas << VF;  v' = 0
//   hold-off (typ 3):  p' = p + v        (v unchanged; same adder: a = p, shift 0)
//   E1: a = move ? m - p : p (subtract) -> E2: s = (a >>> sh) + v (shift, add)
//   -> E3: r = clamp(s) for a move, s for a hold-off update (two compares, select)
//   -> E4 registers: p' = m + r (move), m (new), r (hold-off) on p_o.
// The clamp is the max-speed setting (by design, not an overflow).  No multiplier.
// Twin: sim/fmt/tracker.py (Tracker.step, "update").
`default_nettype none

module fmt_tracker_vel #(
    parameter VF  = 12,           // extra fraction bits of p and v
    parameter V_W = 22,           // velocity width (signed)
    parameter P_W = 36            // prediction width (signed), >= 16 + VF + 2
) (
    input  wire            clk,
    input  wire [1:0]      typ_i,    // E1: 0 new, 1 move, 3 hold-off update (2: unused)
    input  wire [15:0]     meas_i,   // E1: measured coordinate, unsigned Q8.8
    input  wire [P_W-1:0]  p_i,      // E1: prediction, signed Q.(8+VF)
    input  wire [V_W-1:0]  v_i,      // E1: velocity, signed, 2^-(8+VF) cells/frame
    input  wire [3:0]      shift_i,  // filter gain 2^-shift (setting)
    input  wire [V_W-2:0]  vmax_i,   // clamp magnitude (setting)
    output reg  [P_W-1:0]  p_o,      // E4: new prediction
    output wire [V_W-1:0]  v_o       // E4: new velocity (0 for new; unused for hold-off)
);

    localparam E_W = P_W + 2;
    localparam [1:0] T_NEW = 2'd0, T_MOVE = 2'd1, T_UPD = 2'd3;

    // ---- E1: prediction error (move) or p (hold-off update) ---------------------------
    wire signed [E_W-1:0] m1  = $signed({{(E_W-16-VF){1'b0}}, meas_i, {VF{1'b0}}});
    wire signed [E_W-1:0] p1  = $signed({{2{p_i[P_W-1]}}, p_i});
    wire                  up1 = (typ_i == T_UPD);
    reg  signed [E_W-1:0] a2_q;
    reg         [V_W-1:0] v2_q;
    reg         [3:0]     sh2_q;
    reg         [1:0]     typ2_q, typ3_q, typ4_q;
    reg         [15:0]    m2_q, m3_q, m4_q;
    always @(posedge clk) begin
        a2_q   <= up1 ? p1 : m1 - p1;
        v2_q   <= v_i;
        sh2_q  <= up1 ? 4'd0 : shift_i;
        typ2_q <= typ_i;
        m2_q   <= meas_i;
    end

    // ---- E2: (a >>> sh) + v ---------------------------------------------------------------
    wire signed [E_W-1:0] s2 = (a2_q >>> sh2_q) + $signed({{(E_W-V_W){v2_q[V_W-1]}}, v2_q});
    reg  signed [E_W-1:0] s3_q;
    always @(posedge clk) begin
        s3_q   <= s2;
        typ3_q <= typ2_q;
        m3_q   <= m2_q;
    end

    // ---- E3: clamp to +-vmax (compares as sign bits of vmax - s and s + vmax) ----------
    wire signed [E_W:0]   vm3 = $signed({{(E_W-V_W+2){1'b0}}, vmax_i});
    wire signed [E_W:0]   s3x = $signed({s3_q[E_W-1], s3_q});
    wire signed [E_W:0]   hi3 = vm3 - s3x;        // < 0: s > vmax
    wire signed [E_W:0]   lo3 = s3x + vm3;        // < 0: s < -vmax
    wire        [V_W-1:0] vmx = {1'b0, vmax_i};
    reg         [V_W-1:0] c3;
    always @* begin
        if (hi3[E_W])
            c3 = vmx;
        else if (lo3[E_W])
            c3 = -vmx;
        else
            c3 = s3_q[V_W-1:0];
    end
    reg [P_W-1:0] r4_q;
    always @(posedge clk) begin
        r4_q   <= (typ3_q == T_UPD) ? s3_q[P_W-1:0] : {{(P_W-V_W){c3[V_W-1]}}, c3};
        typ4_q <= typ3_q;
        m4_q   <= m3_q;
    end

    // ---- E4: outputs ---------------------------------------------------------------------
    wire [P_W-1:0] m4 = {{(P_W-16-VF){1'b0}}, m4_q, {VF{1'b0}}};
    always @* begin
        case (typ4_q)
            T_MOVE:  p_o = m4 + r4_q;
            T_NEW:   p_o = m4;
            default: p_o = r4_q;
        endcase
    end
    assign v_o = (typ4_q == T_MOVE) ? r4_q[V_W-1:0] : {V_W{1'b0}};

endmodule

`default_nettype wire
