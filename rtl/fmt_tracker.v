// fmt_tracker -- frame matching: stable contact IDs, new / move / lift events.
//
// Twin: sim/fmt/tracking.py (Tracker.step), bit-exact (same events, same order).
//
// Contact table: MAX_TOUCHES slots, each with active flag, generation counter,
// predicted position p (signed, Q.(8+VF): Q8.8 cells with VF extra fraction bits),
// velocity v (signed V_W bits, 2^-(8+VF) cells/frame), miss counter (frames since
// last seen) and last measured position (for the lift event).
//
// Per frame:
//   COLLECT  touches arrive (tp_valid, any cycles).  In the cycle a touch arrives its
//            L1 distance to the (rounded) prediction of every slot is computed in
//            parallel, D = |x - (px + 2^(VF-1) >> VF)| + |y - ...|, and stored with a
//            candidate bit = slot active and D <= gate (max_jump_i for a contact seen
//            last frame, hold_jump_i for one in hold-off).  Touches beyond MAX_TOUCHES
//            are dropped (sticky drop_flag_o).
//   MATCH    (after tp_eof) one greedy step per 2 cycles: a min tree over the
//            MAX_TOUCHES^2 candidate matrix (unassigned touches and slots), pipelined
//            in two stages (per-touch minima over the slots, registered; then the
//            minimum over the touches), picks the smallest D, ties to the smallest
//            index t * 2^SB + s; the pair is assigned; in the next cycle a move event
//            is issued and the slot's velocity/prediction updated:
//              e = (x << VF) - p;  v = clamp(v + (e >>> vel_shift_i), +-max_speed_i);
//              p = (x << VF) + v.
//            No candidate left -> LIFT.
//   LIFT     one lift per cycle, lowest slot first, for each active unmatched slot
//            with miss + 1 >= hold_off_i (the slot becomes free).
//   NEW      one per cycle, unassigned touches in arrival order: the first free slot
//            at or after the round-robin pointer; generation + 1; id = {gen, slot};
//            no free slot -> the touch is dropped (sticky noslot_flag_o).
//   UPDATE   one cycle: every active slot neither matched nor new: miss + 1, p += v.
// Events leave through a one-event holding register (to mark ev_last_o).  With m
// matches, l lifts, n news and d new touches without a free slot, the frame's last
// event is on the output 2m + l + n + d + 6 cycles after the tp_eof cycle (tp_eof ->
// MATCH 1, the empty MATCH step 2, empty LIFT/NEW steps 2, UPDATE and hold 1).
// A frame with no events emits nothing.  Touches of the next frame must not arrive
// before the tracker is idle again (overrun_flag_o; they are dropped).
// tp_frame_i is sampled with every touch and with tp_eof (the event frame number).
//
// Fixed-point formats: x, y, axes unsigned Q8.8 cells; gates Q8.8 (L1); p signed
// P_W = 16 + VF + 8 bits; e >>> vel_shift is an arithmetic shift (floor); velocity
// clamp is saturation by design (the max speed setting), not an error.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_tracker #(
    parameter MAX_TOUCHES = `FMT_MAX_TOUCHES,  // contact slots = touches per frame
    parameter HM_W        = `FMT_HM_W,         // strength width
    parameter FRAME_W     = 16,                // frame number width
    parameter ID_W        = 8,                 // contact ID width ({generation, slot})
    parameter VF          = 12,                // extra fraction bits of p and v
    parameter V_W         = 22,                // velocity width (signed)
    parameter HOLD_W      = 12,                // miss counter / hold-off width
    parameter SB          = (MAX_TOUCHES > 1) ? $clog2(MAX_TOUCHES) : 1  // slot index bits
) (
    input  wire                  clk,
    input  wire                  rst,              // synchronous, active high
    // settings (run time, from the register file)
    input  wire [15:0]           max_jump_i,       // L1 gate, contact seen last frame (Q8.8)
    input  wire [15:0]           hold_jump_i,      // L1 gate, contact in hold-off (Q8.8)
    input  wire [HOLD_W-1:0]     hold_off_i,       // frames missing before lift (0 acts as 1)
    input  wire [3:0]            vel_shift_i,      // velocity filter gain 2^-S, S <= VF
    input  wire [V_W-2:0]        max_speed_i,      // |v| clamp per axis, 2^-(8+VF) cells/frame
    // touch stream in (fmt_interp)
    input  wire                  tp_valid_i,       // one touch this cycle
    input  wire [FRAME_W-1:0]    tp_frame_i,       // frame number (with tp_valid and tp_eof)
    input  wire [15:0]           tp_x_i,           // Q8.8 column coordinate
    input  wire [15:0]           tp_y_i,           // Q8.8 row coordinate
    input  wire [HM_W-1:0]       tp_strength_i,    // peak cell value
    input  wire [15:0]           tp_axis_major_i,  // Q8.8 semi-axis
    input  wire [15:0]           tp_axis_minor_i,  // Q8.8 semi-axis
    input  wire [7:0]            tp_angle_i,       // pi/256 units
    input  wire [7:0]            tp_flags_i,       // fit flags
    input  wire                  tp_eof_i,         // end of the frame's touches
    // event stream out (no back-pressure: fmt_event_port buffers)
    output reg                   ev_valid_o,       // one event this cycle
    output reg  [FRAME_W-1:0]    ev_frame_o,       // frame number
    output reg  [ID_W-1:0]       ev_id_o,          // contact ID
    output reg  [1:0]            ev_type_o,        // 0 new, 1 move, 2 lift
    output reg  [15:0]           ev_x_o,           // Q8.8
    output reg  [15:0]           ev_y_o,           // Q8.8
    output reg  [HM_W-1:0]       ev_strength_o,    // peak (0 for lift)
    output reg  [15:0]           ev_axis_major_o,  // Q8.8 (0 for lift)
    output reg  [15:0]           ev_axis_minor_o,  // Q8.8 (0 for lift)
    output reg  [7:0]            ev_angle_o,       // pi/256 (0 for lift)
    output reg  [7:0]            ev_flags_o,       // fit flags (0 for lift)
    output reg                   ev_last_o,        // last event of the frame
    // status (sticky until rst)
    output reg                   drop_flag_o,      // a frame had more than MAX_TOUCHES touches
    output reg                   noslot_flag_o,    // a new touch found no free slot
    output reg                   overrun_flag_o,   // input while busy (dropped)
    output wire                  busy_o            // not idle (matching / emitting)
);

    // ---- sizes ----------------------------------------------------------------------
    localparam MT    = MAX_TOUCHES;
    localparam MTP   = 1 << SB;              // slots padded to a power of two
    localparam NL    = MTP * MTP;            // leaves of the min tree
    localparam LW    = 2 * SB;               // leaf index width
    localparam TCW   = $clog2(MT + 1);       // touch counter width
    localparam GEN_W = ID_W - SB;            // generation bits
    localparam P_W   = 16 + VF + 8;          // prediction width (signed)
    localparam PI_W  = P_W - VF;             // integer (Q8.8) part of a prediction
    localparam DW    = 16;                   // stored distance (candidates are <= 16 bits)
    localparam KW    = DW + 1;               // tree key {invalid, D}
    localparam TD_W  = 16 + 16 + HM_W + 16 + 16 + 8 + 8;  // touch record width

    localparam [2:0] S_IDLE = 3'd0, S_MATCH = 3'd1, S_LIFT = 3'd2, S_NEW = 3'd3, S_UPD = 3'd4;
    localparam [1:0] T_NEW = 2'd0, T_MOVE = 2'd1, T_LIFT = 2'd2;

    // ---- state ------------------------------------------------------------------------
    reg [2:0]          state_q;
    reg [FRAME_W-1:0]  frame_q;
    reg [TCW-1:0]      tcnt_q;                    // touches stored this frame
    reg [MT*TD_W-1:0]  touch_q;                   // touch records {x,y,str,maj,min,ang,flg}
    reg [NL*DW-1:0]    dist_q;                    // D of leaf t*MTP+s
    reg [NL-1:0]       cand_q;                    // candidate bit of leaf t*MTP+s
    reg [MT-1:0]       tused_q;                   // touch assigned (matched / new / dropped)
    reg [MT-1:0]       sused_q;                   // slot matched or newly allocated
    reg [MT-1:0]       act_q;                     // slot active
    reg [MT*GEN_W-1:0] gen_q;
    reg [MT*P_W-1:0]   px_q, py_q;
    reg [MT*V_W-1:0]   vx_q, vy_q;
    reg [MT*HOLD_W-1:0] miss_q;
    reg [MT*16-1:0]    lx_q, ly_q;
    reg [SB-1:0]       next_slot_q;               // round-robin allocation pointer
    reg                mph_q;                     // MATCH phase: 0 tree stage A, 1 stage B
    // event holding register
    reg                pend_q;
    reg [ID_W-1:0]     pid_q;
    reg [1:0]          ptype_q;
    reg [TD_W-1:0]     pdata_q;

    assign busy_o = (state_q != S_IDLE);

    // ---- predictions and gates (combinational from the slot state) -------------------
    reg [MT*PI_W-1:0] predx, predy;
    reg [MT*16-1:0]   gate;
    integer s_i;
    always @* begin
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            predx[s_i*PI_W +: PI_W] = pred_of(px_q[s_i*P_W +: P_W]);
            predy[s_i*PI_W +: PI_W] = pred_of(py_q[s_i*P_W +: P_W]);
            gate[s_i*16 +: 16] = (miss_q[s_i*HOLD_W +: HOLD_W] == {HOLD_W{1'b0}}) ? max_jump_i
                                                                               : hold_jump_i;
        end
    end

    // round half up: (p + 2^(VF-1)) >>> VF
    function [PI_W-1:0] pred_of;
        input [P_W-1:0] p;
        /* verilator lint_off UNUSEDSIGNAL */   // the low VF bits are the dropped fraction
        reg   [P_W-1:0] r;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            r = p + ({{(P_W-1){1'b0}}, 1'b1} << (VF - 1));
            pred_of = r[P_W-1:VF];
        end
    endfunction

    // ---- distances of the arriving touch to every slot ---------------------------
    reg [MT*DW-1:0] dnew;       // saturated D per slot
    reg [MT-1:0]    cnew;       // candidate per slot
    reg signed [PI_W:0] ddx, ddy;
    reg [PI_W+1:0]  dsum;
    always @* begin
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            ddx = $signed({{(PI_W-15){1'b0}}, tp_x_i}) - $signed({predx[s_i*PI_W+PI_W-1], predx[s_i*PI_W +: PI_W]});
            ddy = $signed({{(PI_W-15){1'b0}}, tp_y_i}) - $signed({predy[s_i*PI_W+PI_W-1], predy[s_i*PI_W +: PI_W]});
            dsum = {1'b0, (ddx < 0) ? -ddx : ddx} + {1'b0, (ddy < 0) ? -ddy : ddy};
            cnew[s_i] = act_q[s_i] && (dsum <= {{(PI_W+2-16){1'b0}}, gate[s_i*16 +: 16]});
            dnew[s_i*DW +: DW] = dsum[DW-1:0];
        end
    end

    // ---- min tree over the candidate matrix, two pipeline stages ----------------------
    // Leaf t*MTP+s = {invalid, D}.  Stage A (MATCH phase 0): the first SB levels reduce
    // over s for each touch t -> per-touch minima, registered.  Stage B (MATCH phase
    // 1): the last SB levels reduce over t.  Ties always go to the lower index, so the
    // result is the smallest (D, t, s) -- the same as one flat tree.
    reg [NL*KW-1:0]  tk;        // stage A keys, reduced in place
    reg [NL*LW-1:0]  ti;        // stage A leaf indices
    reg [MTP*KW-1:0] rk_q;      // registered per-touch minima
    reg [MTP*LW-1:0] ri_q;
    reg [MTP*KW-1:0] bk;        // stage B keys, reduced in place
    reg [MTP*LW-1:0] bi;
    reg              m_found;
    reg [SB-1:0]     m_s;
    reg [SB-1:0]     m_t;
    integer l_i, n_i, t_i;
    always @* begin
        for (t_i = 0; t_i < MTP; t_i = t_i + 1) begin
            for (s_i = 0; s_i < MTP; s_i = s_i + 1) begin
                if (t_i < MT && s_i < MT) begin
                    tk[(t_i*MTP+s_i)*KW +: KW] = {~(cand_q[t_i*MTP+s_i] & ~tused_q[t_i] & ~sused_q[s_i]),
                                                  dist_q[(t_i*MTP+s_i)*DW +: DW]};
                end else begin
                    tk[(t_i*MTP+s_i)*KW +: KW] = {KW{1'b1}};
                end
                ti[(t_i*MTP+s_i)*LW +: LW] = {t_i[SB-1:0], s_i[SB-1:0]};
            end
        end
        // level by level: node i <- min(node 2i, node 2i+1), ties to the left (lower index)
        for (n_i = NL / 2; n_i >= MTP; n_i = n_i / 2) begin
            for (l_i = 0; l_i < n_i; l_i = l_i + 1) begin
                if (tk[(2*l_i+1)*KW +: KW] < tk[(2*l_i)*KW +: KW]) begin
                    tk[l_i*KW +: KW] = tk[(2*l_i+1)*KW +: KW];
                    ti[l_i*LW +: LW] = ti[(2*l_i+1)*LW +: LW];
                end else begin
                    tk[l_i*KW +: KW] = tk[(2*l_i)*KW +: KW];
                    ti[l_i*LW +: LW] = ti[(2*l_i)*LW +: LW];
                end
            end
        end
    end
    always @* begin
        bk = rk_q;
        bi = ri_q;
        for (n_i = MTP / 2; n_i >= 1; n_i = n_i / 2) begin
            for (l_i = 0; l_i < n_i; l_i = l_i + 1) begin
                if (bk[(2*l_i+1)*KW +: KW] < bk[(2*l_i)*KW +: KW]) begin
                    bk[l_i*KW +: KW] = bk[(2*l_i+1)*KW +: KW];
                    bi[l_i*LW +: LW] = bi[(2*l_i+1)*LW +: LW];
                end else begin
                    bk[l_i*KW +: KW] = bk[(2*l_i)*KW +: KW];
                    bi[l_i*LW +: LW] = bi[(2*l_i)*LW +: LW];
                end
            end
        end
        m_found = ~bk[KW-1];
        m_t = bi[LW-1:SB];
        m_s = bi[SB-1:0];
    end

    // ---- the matched pair's update (one shared datapath) ------------------------
    // registered pair: the slot update and the move event happen the cycle after the
    // tree's stage B (a MATCH phase-0 cycle), off the tree's critical path
    reg               mv_q;
    reg [SB-1:0]      mv_s_q, mv_t_q;
    // Variable-index reads are written as AND-OR selects over constant slices (and the
    // writes below as per-entry enables): a part-select at a computed offset would
    // synthesize to a barrel shifter over the whole vector.
    reg [TD_W-1:0]    m_touch, n_touch;
    reg [P_W-1:0]     m_px, m_py;
    reg [V_W-1:0]     m_vx, m_vy;
    reg [GEN_W-1:0]   m_gen, l_gen, f_gen_old;
    reg [15:0]        l_lx, l_ly;
    wire [15:0]       m_x     = m_touch[TD_W-1 -: 16];
    wire [15:0]       m_y     = m_touch[TD_W-17 -: 16];
    wire [V_W-1:0]    m_vx_new, m_vy_new;
    wire [P_W-1:0]    m_px_new, m_py_new;

    fmt_tracker_vel #(.VF(VF), .V_W(V_W), .P_W(P_W)) u_velx (
        .meas_i(m_x), .p_i(m_px), .v_i(m_vx),
        .shift_i(vel_shift_i), .vmax_i(max_speed_i), .v_o(m_vx_new), .p_o(m_px_new));
    fmt_tracker_vel #(.VF(VF), .V_W(V_W), .P_W(P_W)) u_vely (
        .meas_i(m_y), .p_i(m_py), .v_i(m_vy),
        .shift_i(vel_shift_i), .vmax_i(max_speed_i), .v_o(m_vy_new), .p_o(m_py_new));

    // ---- lifts: lowest active unmatched slot whose hold-off expires --------------
    reg [MT-1:0] lift_mask;
    reg          l_found;
    reg [SB-1:0] l_s;
    always @* begin
        for (s_i = 0; s_i < MT; s_i = s_i + 1)
            lift_mask[s_i] = act_q[s_i] & ~sused_q[s_i] &
                ({1'b0, miss_q[s_i*HOLD_W +: HOLD_W]} + 1'b1 >= {1'b0, hold_off_i});
        l_found = |lift_mask;
        l_s = {SB{1'b0}};
        for (s_i = MT - 1; s_i >= 0; s_i = s_i - 1)
            if (lift_mask[s_i]) l_s = s_i[SB-1:0];
    end

    // ---- news: lowest unassigned touch, first free slot from the pointer -----------
    reg          n_found, f_found;
    reg [SB-1:0] n_t, f_s;
    reg [SB:0]   idx;
    integer k_i;
    always @* begin
        n_found = 1'b0;
        n_t = {SB{1'b0}};
        for (t_i = MT - 1; t_i >= 0; t_i = t_i - 1)
            if (t_i < tcnt_q && !tused_q[t_i]) begin
                n_found = 1'b1;
                n_t = t_i[SB-1:0];
            end
        f_found = 1'b0;
        f_s = {SB{1'b0}};
        for (k_i = MT - 1; k_i >= 0; k_i = k_i - 1) begin
            idx = {1'b0, next_slot_q} + k_i[SB:0];
            if (idx >= MT) idx = idx - MT;
            if (!act_q[idx[SB-1:0]]) begin
                f_found = 1'b1;
                f_s = idx[SB-1:0];
            end
        end
    end
    // selects of the registered pair, the lifted slot, the new touch and its slot
    integer q_i;
    always @* begin
        m_touch = {TD_W{1'b0}};
        n_touch = {TD_W{1'b0}};
        m_px = {P_W{1'b0}};
        m_py = {P_W{1'b0}};
        m_vx = {V_W{1'b0}};
        m_vy = {V_W{1'b0}};
        m_gen = {GEN_W{1'b0}};
        l_gen = {GEN_W{1'b0}};
        f_gen_old = {GEN_W{1'b0}};
        l_lx = 16'd0;
        l_ly = 16'd0;
        for (q_i = 0; q_i < MT; q_i = q_i + 1) begin
            m_touch = m_touch | (touch_q[q_i*TD_W +: TD_W] & {TD_W{mv_t_q == q_i[SB-1:0]}});
            n_touch = n_touch | (touch_q[q_i*TD_W +: TD_W] & {TD_W{n_t == q_i[SB-1:0]}});
            m_px  = m_px  | (px_q[q_i*P_W +: P_W] & {P_W{mv_s_q == q_i[SB-1:0]}});
            m_py  = m_py  | (py_q[q_i*P_W +: P_W] & {P_W{mv_s_q == q_i[SB-1:0]}});
            m_vx  = m_vx  | (vx_q[q_i*V_W +: V_W] & {V_W{mv_s_q == q_i[SB-1:0]}});
            m_vy  = m_vy  | (vy_q[q_i*V_W +: V_W] & {V_W{mv_s_q == q_i[SB-1:0]}});
            m_gen = m_gen | (gen_q[q_i*GEN_W +: GEN_W] & {GEN_W{mv_s_q == q_i[SB-1:0]}});
            l_gen = l_gen | (gen_q[q_i*GEN_W +: GEN_W] & {GEN_W{l_s == q_i[SB-1:0]}});
            f_gen_old = f_gen_old | (gen_q[q_i*GEN_W +: GEN_W] & {GEN_W{f_s == q_i[SB-1:0]}});
            l_lx  = l_lx  | (lx_q[q_i*16 +: 16] & {16{l_s == q_i[SB-1:0]}});
            l_ly  = l_ly  | (ly_q[q_i*16 +: 16] & {16{l_s == q_i[SB-1:0]}});
        end
    end
    wire [GEN_W-1:0] f_gen   = f_gen_old + 1'b1;
    wire [SB-1:0]    f_next  = ({1'b0, f_s} == MT - 1) ? {SB{1'b0}} : f_s + 1'b1;

    // ---- the sequencer ------------------------------------------------------------
    reg              gen_ev;           // an event is formed this cycle
    reg [ID_W-1:0]   gen_id;
    reg [1:0]        gen_type;
    reg [TD_W-1:0]   gen_data;
    always @* begin
        gen_ev = 1'b0;
        gen_id = {ID_W{1'b0}};
        gen_type = T_MOVE;
        gen_data = {TD_W{1'b0}};
        case (state_q)
            S_MATCH: if (mv_q) begin
                gen_ev = 1'b1;
                gen_id = {m_gen, mv_s_q};
                gen_type = T_MOVE;
                gen_data = m_touch;
            end
            S_LIFT: if (l_found) begin
                gen_ev = 1'b1;
                gen_id = {l_gen, l_s};
                gen_type = T_LIFT;
                gen_data = {l_lx, l_ly, {(TD_W-32){1'b0}}};
            end
            S_NEW: if (n_found && f_found) begin
                gen_ev = 1'b1;
                gen_id = {f_gen, f_s};
                gen_type = T_NEW;
                gen_data = n_touch;
            end
            default: ;
        endcase
    end

    wire frame_done = (state_q == S_UPD);

    always @(posedge clk) begin
        if (rst) begin
            state_q        <= S_IDLE;
            frame_q        <= {FRAME_W{1'b0}};
            tcnt_q         <= {TCW{1'b0}};
            touch_q        <= {(MT*TD_W){1'b0}};
            dist_q         <= {(NL*DW){1'b0}};
            cand_q         <= {NL{1'b0}};
            tused_q        <= {MT{1'b0}};
            sused_q        <= {MT{1'b0}};
            act_q          <= {MT{1'b0}};
            gen_q          <= {(MT*GEN_W){1'b0}};
            px_q           <= {(MT*P_W){1'b0}};
            py_q           <= {(MT*P_W){1'b0}};
            vx_q           <= {(MT*V_W){1'b0}};
            vy_q           <= {(MT*V_W){1'b0}};
            miss_q         <= {(MT*HOLD_W){1'b0}};
            lx_q           <= {(MT*16){1'b0}};
            ly_q           <= {(MT*16){1'b0}};
            next_slot_q    <= {SB{1'b0}};
            mph_q          <= 1'b0;
            mv_q           <= 1'b0;
            mv_s_q         <= {SB{1'b0}};
            mv_t_q         <= {SB{1'b0}};
            rk_q           <= {(MTP*KW){1'b1}};
            ri_q           <= {(MTP*LW){1'b0}};
            pend_q         <= 1'b0;
            pid_q          <= {ID_W{1'b0}};
            ptype_q        <= 2'd0;
            pdata_q        <= {TD_W{1'b0}};
            ev_valid_o     <= 1'b0;
            ev_frame_o     <= {FRAME_W{1'b0}};
            ev_id_o        <= {ID_W{1'b0}};
            ev_type_o      <= 2'd0;
            ev_x_o         <= 16'd0;
            ev_y_o         <= 16'd0;
            ev_strength_o  <= {HM_W{1'b0}};
            ev_axis_major_o <= 16'd0;
            ev_axis_minor_o <= 16'd0;
            ev_angle_o     <= 8'd0;
            ev_flags_o     <= 8'd0;
            ev_last_o      <= 1'b0;
            drop_flag_o    <= 1'b0;
            noslot_flag_o  <= 1'b0;
            overrun_flag_o <= 1'b0;
        end else begin
            // ---- input side --------------------------------------------------------
            if (state_q == S_IDLE) begin
                if (tp_valid_i) begin
                    frame_q <= tp_frame_i;
                    if (tcnt_q < MT) begin
                        for (t_i = 0; t_i < MT; t_i = t_i + 1) begin
                            if (tcnt_q == t_i[TCW-1:0]) begin
                                touch_q[t_i*TD_W +: TD_W] <= {tp_x_i, tp_y_i, tp_strength_i,
                                    tp_axis_major_i, tp_axis_minor_i, tp_angle_i, tp_flags_i};
                                for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
                                    dist_q[(t_i*MTP+s_i)*DW +: DW] <= dnew[s_i*DW +: DW];
                                    cand_q[t_i*MTP+s_i] <= cnew[s_i];
                                end
                            end
                        end
                        tcnt_q <= tcnt_q + 1'b1;
                    end else begin
                        drop_flag_o <= 1'b1;
                    end
                end
                if (tp_eof_i) begin
                    frame_q <= tp_frame_i;
                    state_q <= S_MATCH;
                end
            end else if (tp_valid_i || tp_eof_i) begin
                overrun_flag_o <= 1'b1;
            end

            // ---- the matched pair's slot update (one cycle after stage B) --------------
            mv_q <= 1'b0;
            for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
                if (mv_q && mv_s_q == s_i[SB-1:0]) begin
                    vx_q[s_i*V_W +: V_W] <= m_vx_new;
                    vy_q[s_i*V_W +: V_W] <= m_vy_new;
                    px_q[s_i*P_W +: P_W] <= m_px_new;
                    py_q[s_i*P_W +: P_W] <= m_py_new;
                    miss_q[s_i*HOLD_W +: HOLD_W] <= {HOLD_W{1'b0}};
                    lx_q[s_i*16 +: 16] <= m_x;
                    ly_q[s_i*16 +: 16] <= m_y;
                end
            end

            // ---- matching / lifts / news / update -------------------------------------
            case (state_q)
                S_MATCH: begin
                    mph_q <= ~mph_q;
                    if (!mph_q) begin
                        rk_q <= tk[MTP*KW-1:0];
                        ri_q <= ti[MTP*LW-1:0];
                    end else if (m_found) begin
                        tused_q[m_t] <= 1'b1;
                        sused_q[m_s] <= 1'b1;
                        mv_q   <= 1'b1;
                        mv_s_q <= m_s;
                        mv_t_q <= m_t;
                    end else begin
                        state_q <= S_LIFT;
                    end
                end
                S_LIFT: begin
                    if (l_found) act_q[l_s] <= 1'b0;
                    else         state_q <= S_NEW;
                end
                S_NEW: begin
                    if (n_found) begin
                        tused_q[n_t] <= 1'b1;
                        if (f_found) begin
                            act_q[f_s]  <= 1'b1;
                            sused_q[f_s] <= 1'b1;
                            for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
                                if (f_s == s_i[SB-1:0]) begin
                                    gen_q[s_i*GEN_W +: GEN_W] <= f_gen;
                                    px_q[s_i*P_W +: P_W] <= {{(P_W-16-VF){1'b0}}, n_touch[TD_W-1 -: 16], {VF{1'b0}}};
                                    py_q[s_i*P_W +: P_W] <= {{(P_W-16-VF){1'b0}}, n_touch[TD_W-17 -: 16], {VF{1'b0}}};
                                    vx_q[s_i*V_W +: V_W] <= {V_W{1'b0}};
                                    vy_q[s_i*V_W +: V_W] <= {V_W{1'b0}};
                                    miss_q[s_i*HOLD_W +: HOLD_W] <= {HOLD_W{1'b0}};
                                    lx_q[s_i*16 +: 16] <= n_touch[TD_W-1 -: 16];
                                    ly_q[s_i*16 +: 16] <= n_touch[TD_W-17 -: 16];
                                end
                            end
                            next_slot_q <= f_next;
                        end else begin
                            noslot_flag_o <= 1'b1;
                        end
                    end else begin
                        state_q <= S_UPD;
                    end
                end
                S_UPD: begin
                    for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
                        if (act_q[s_i] && !sused_q[s_i]) begin
                            miss_q[s_i*HOLD_W +: HOLD_W] <= miss_q[s_i*HOLD_W +: HOLD_W] + 1'b1;
                            px_q[s_i*P_W +: P_W] <= px_q[s_i*P_W +: P_W] +
                                {{(P_W-V_W){vx_q[s_i*V_W+V_W-1]}}, vx_q[s_i*V_W +: V_W]};
                            py_q[s_i*P_W +: P_W] <= py_q[s_i*P_W +: P_W] +
                                {{(P_W-V_W){vy_q[s_i*V_W+V_W-1]}}, vy_q[s_i*V_W +: V_W]};
                        end
                    end
                    tcnt_q  <= {TCW{1'b0}};
                    tused_q <= {MT{1'b0}};
                    sused_q <= {MT{1'b0}};
                    cand_q  <= {NL{1'b0}};
                    state_q <= S_IDLE;
                end
                default: ;
            endcase

            // ---- event output through the holding register ----------------------------
            ev_valid_o <= 1'b0;
            if (pend_q && (gen_ev || frame_done)) begin
                ev_valid_o      <= 1'b1;
                ev_frame_o      <= frame_q;
                ev_id_o         <= pid_q;
                ev_type_o       <= ptype_q;
                {ev_x_o, ev_y_o, ev_strength_o, ev_axis_major_o, ev_axis_minor_o,
                 ev_angle_o, ev_flags_o} <= pdata_q;
                ev_last_o       <= frame_done;
            end
            if (gen_ev) begin
                pend_q  <= 1'b1;
                pid_q   <= gen_id;
                ptype_q <= gen_type;
                pdata_q <= gen_data;
            end else if (frame_done) begin
                pend_q <= 1'b0;
            end
        end
    end

endmodule

`default_nettype wire
