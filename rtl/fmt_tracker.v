// fmt_tracker -- frame matching: stable contact IDs, new / move / lift events.
//
// Twin: sim/fmt/tracker.py (Tracker.step), bit-exact (same events, same order); the
// cycle count of the match is modelled by tracking.lazy_greedy (see MATCH below).
//
// Contact table: MAX_TOUCHES slots.  In flip-flops (read by all slots in parallel):
// active flag, miss counter (frames since last seen), generation counter and the
// rounded prediction pred = (p + 2^(VF-1)) >>> VF per axis, formed the cycle after p
// is written and clamped to PR_W = 18 bits signed, [-2^17, 2^17) (exact for the gate test: a
// prediction outside that range is, clamped or not, more than 65535 from any x in
// [0, 65535], so never a candidate).  In a LUT RAM (one word per slot, one slot per
// cycle; written by NEW before it is read, so not reset): predicted position p
// (signed, Q.(8+VF): Q8.8 cells with VF extra fraction bits), velocity v (signed V_W
// bits, 2^-(8+VF) cells/frame) and last measured position (for the lift event).
//
// Per frame:
//   COLLECT  touches arrive (tp_valid, any cycles).  In the cycle a touch arrives its
//            record goes to a LUT RAM and its L1 distance to the prediction of every
//            slot is computed in parallel, D = |x - pred_x| + |y - pred_y|, and
//            stored (one LUT-RAM row per touch, D kept to 16 bits) with
//            a candidate bit = slot active and D <= gate (max_jump_i for a contact
//            seen last frame, hold_jump_i for one in hold-off).  The next cycle the row
//            is read back and one shared min tree over the slots (ties to the lower
//            slot) caches the touch's best key (D, s) in a register.  Touches beyond
//            MAX_TOUCHES are dropped (sticky drop_flag_o).
//   MATCH    (after tp_eof) greedy nearest pairs, smallest (D, t, s) first -- ties to
//            the smallest index t * 2^SB + s -- with lazily refreshed per-touch minima:
//            a second min tree picks the smallest cached key (D_t, t) of the
//            unassigned touches.  Cached keys only grow as slots are taken, so each is
//            a lower bound of that touch's current key: if the picked touch's cached
//            slot is still free the pair IS the global greedy choice and is assigned
//            (1 cycle); otherwise the pick is stale: the touch's row is re-read and
//            its minimum over the free slots recomputed (2 cycles in all), and the
//            pick repeats.  The
//            cycle after an assignment a move event is issued and the slot's
//            velocity/prediction updated:
//              e = (x << VF) - p;  v = clamp(v + (e >>> vel_shift_i), +-max_speed_i);
//              p = (x << VF) + v.
//            No candidate left -> LIFT.  Stale picks: none when every touch's nearest
//            slot is its own; at most one per remaining touch per assignment, i.e.
//            <= MT(MT-1)/2 = 120 at 16 slots (all touches ranking the slots alike).
//   LIFT     one lift per cycle, lowest slot first, for each active unmatched slot
//            with miss + 1 >= hold_off_i (the slot becomes free).
//   NEW      one per cycle, unassigned touches in arrival order: the first free slot
//            at or after the round-robin pointer; generation + 1; id = {gen, slot};
//            no free slot -> the touch is dropped (sticky noslot_flag_o).  The cycle
//            that finds no touch left marks the frame's last event.
//   UPDATE   after the last event, one slot per cycle, lowest first: every active slot
//            neither matched nor new (a contact in hold-off): miss + 1, p += v; then
//            one cycle to clear the frame.  busy_o stays high until then.
// Events leave through a one-event holding register (to mark ev_last_o).  With m
// matches, k stale picks, l lifts, n news and d new touches without a free slot, the
// frame's last event is on the output m + 2k + l + n + d + 4 cycles after the tp_eof
// cycle (MATCH m + 2k + 1, LIFT l + 1, NEW n + d + 1, holding register 1); one more
// when the last touch arrives in the tp_eof cycle.  (Before the lazy minima: 2m + l +
// n + d + 6.)  Worst case 16 + 240 + 4 = 260 at 16 touches and slots, well inside a
// frame of 768 clk at 3 x fs.  busy_o falls h + 1 cycles after the last event (h =
// contacts in hold-off).  A frame with no events emits nothing.  Touches of the next
// frame must not arrive before the tracker is idle again (overrun_flag_o; they are
// dropped).  tp_frame_i is sampled with every touch and with tp_eof (event frame).
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
    output wire                  busy_o            // not idle (matching / emitting / updating)
);

    // ---- sizes ----------------------------------------------------------------------
    localparam MT    = MAX_TOUCHES;
    localparam MTP   = 1 << SB;              // slots padded to a power of two (tree leaves)
    localparam TCW   = $clog2(MT + 1);       // touch counter width
    localparam GEN_W = ID_W - SB;            // generation bits
    localparam P_W   = 16 + VF + 8;          // prediction width (signed)
    localparam PI_W  = P_W - VF;             // integer (Q8.8) part of a prediction
    localparam PR_W  = 18;                   // saturated rounded prediction (signed)
    localparam DW    = 16;                   // stored distance (candidates are <= 16 bits)
    localparam KW    = DW + 1;               // tree key {invalid, D}
    localparam RW    = MT * KW;              // distance-RAM row: {cand, D} per slot
    localparam TD_W  = 16 + 16 + HM_W + 16 + 16 + 8 + 8;  // touch record width
    localparam SD_W  = 2 * P_W + 2 * V_W + 32;            // slot record {px,py,vx,vy,lx,ly}

    localparam [2:0] S_IDLE = 3'd0, S_MATCH = 3'd1, S_LIFT = 3'd2, S_NEW = 3'd3, S_UPD = 3'd4;
    localparam [1:0] T_NEW = 2'd0, T_MOVE = 2'd1, T_LIFT = 2'd2;

    // ---- state ------------------------------------------------------------------------
    reg [2:0]           state_q;
    reg [FRAME_W-1:0]   frame_q;
    reg [TCW-1:0]       tcnt_q;                   // touches stored this frame
    reg                 st_v_q;                   // a row written last cycle: reduce it now
    reg [SB-1:0]        st_t_q;                   // its touch index
    reg [MT-1:0]        kv_q;                     // cached key: touch has a candidate
    reg [MT*DW-1:0]     kd_q;                     // cached key: best D
    reg [MT*SB-1:0]     ks_q;                     // cached key: its slot
    reg                 rc_q;                     // recompute the row of rc_t_q this cycle
    reg [SB-1:0]        rc_t_q;
    reg [MT-1:0]        tused_q;                  // touch assigned (matched / new / dropped)
    reg [MT-1:0]        sused_q;                  // slot matched, newly allocated or updated
    reg [MT-1:0]        act_q;                    // slot active
    reg [MT*HOLD_W-1:0] miss_q;                   // frames since last seen
    reg [MT*PR_W-1:0]   prx_q, pry_q;             // rounded, saturated predictions
    reg [MT*GEN_W-1:0]  gen_q;                    // generation counters
    reg [SB-1:0]        next_slot_q;              // round-robin allocation pointer
    reg                 mv_q;                     // the pair assigned last cycle: move now
    reg [SB-1:0]        mv_s_q, mv_t_q;
    // event holding register
    reg                 pend_q;
    reg [ID_W-1:0]      pid_q;
    reg [1:0]           ptype_q;
    reg [TD_W-1:0]      pdata_q;

    assign busy_o = (state_q != S_IDLE);

    // ---- LUT RAMs (asynchronous read, no reset: a word is written before it is read) --
    reg [RW-1:0]    dmem [0:MTP-1];      // distance rows, written on arrival
    reg [TD_W-1:0]  tmem [0:MTP-1];      // touch records, written on arrival
    reg [SD_W-1:0]  smem [0:MTP-1];      // slot records

    wire            arrive = (state_q == S_IDLE) && tp_valid_i && (tcnt_q < MT);
    wire [SB-1:0]   wa_t   = tcnt_q[SB-1:0];      // < MT when arrive

    // ---- gates and distances of the arriving touch to every slot ------------------
    reg [RW-1:0]       drow;           // {cand, D} per slot
    reg [15:0]         gate;
    reg signed [PR_W:0] ddx, ddy;
    reg [PR_W:0]       dsum;
    // (loop variables are declared in their always block: one driver each, no latch)
    always @* begin : c_drow
        integer s_i;
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            gate = (miss_q[s_i*HOLD_W +: HOLD_W] == {HOLD_W{1'b0}}) ? max_jump_i : hold_jump_i;
            ddx = $signed({{(PR_W-15){1'b0}}, tp_x_i}) -
                  $signed({prx_q[s_i*PR_W+PR_W-1], prx_q[s_i*PR_W +: PR_W]});
            ddy = $signed({{(PR_W-15){1'b0}}, tp_y_i}) -
                  $signed({pry_q[s_i*PR_W+PR_W-1], pry_q[s_i*PR_W +: PR_W]});
            // |ddx|, |ddy| < 2^PR_W: the sum fits PR_W + 1 bits
            dsum = {1'b0, ddx[PR_W-1:0] ^ {PR_W{ddx[PR_W]}}} + {{PR_W{1'b0}}, ddx[PR_W]} +
                   {1'b0, ddy[PR_W-1:0] ^ {PR_W{ddy[PR_W]}}} + {{PR_W{1'b0}}, ddy[PR_W]};
            drow[s_i*KW +: KW] = {act_q[s_i] && (dsum <= {{(PR_W+1-16){1'b0}}, gate}),
                                  dsum[DW-1:0]};
        end
    end

    always @(posedge clk) begin
        if (arrive) begin
            dmem[wa_t] <= drow;
            tmem[wa_t] <= {tp_x_i, tp_y_i, tp_strength_i, tp_axis_major_i, tp_axis_minor_i,
                           tp_angle_i, tp_flags_i};
        end
    end

    // ---- row min tree: one touch's best free slot ---------------------------------
    // Leaves s = {invalid, D}; node <- min(left, right), ties to the left (lower slot).
    wire [SB-1:0]  rr_t   = st_v_q ? st_t_q : rc_t_q;   // row being reduced
    wire [RW-1:0]  rrow   = dmem[rr_t];
    reg [MTP*KW-1:0] rk;
    reg [MTP*SB-1:0] ri;
    reg              r_found;
    reg [DW-1:0]     r_d;
    reg [SB-1:0]     r_s;
    always @* begin : c_rtree
        integer s_i, l_i, n_i;
        for (s_i = 0; s_i < MTP; s_i = s_i + 1) begin
            if (s_i < MT)
                rk[s_i*KW +: KW] = {~(rrow[s_i*KW+DW] & ~sused_q[s_i]), rrow[s_i*KW +: DW]};
            else
                rk[s_i*KW +: KW] = {KW{1'b1}};
            ri[s_i*SB +: SB] = s_i[SB-1:0];
        end
        for (n_i = MTP / 2; n_i >= 1; n_i = n_i / 2) begin
            for (l_i = 0; l_i < n_i; l_i = l_i + 1) begin
                if (rk[(2*l_i+1)*KW +: KW] < rk[(2*l_i)*KW +: KW]) begin
                    rk[l_i*KW +: KW] = rk[(2*l_i+1)*KW +: KW];
                    ri[l_i*SB +: SB] = ri[(2*l_i+1)*SB +: SB];
                end else begin
                    rk[l_i*KW +: KW] = rk[(2*l_i)*KW +: KW];
                    ri[l_i*SB +: SB] = ri[(2*l_i)*SB +: SB];
                end
            end
        end
        r_found = ~rk[KW-1];
        r_d = rk[DW-1:0];
        r_s = ri[SB-1:0];
    end

    // ---- touch min tree: smallest cached key (D_t, t) of the unassigned touches -------
    reg [MTP*KW-1:0] bk;
    reg [MTP*SB-1:0] bi;             // touch index
    reg [MTP*SB-1:0] bs;             // its cached slot
    reg              m_found;
    reg [SB-1:0]     m_t, m_s;
    always @* begin : c_ttree
        integer l_i, n_i, t_i;
        for (t_i = 0; t_i < MTP; t_i = t_i + 1) begin
            if (t_i < MT) begin
                bk[t_i*KW +: KW] = {~(kv_q[t_i] & ~tused_q[t_i]), kd_q[t_i*DW +: DW]};
                bs[t_i*SB +: SB] = ks_q[t_i*SB +: SB];
            end else begin
                bk[t_i*KW +: KW] = {KW{1'b1}};
                bs[t_i*SB +: SB] = {SB{1'b0}};
            end
            bi[t_i*SB +: SB] = t_i[SB-1:0];
        end
        for (n_i = MTP / 2; n_i >= 1; n_i = n_i / 2) begin
            for (l_i = 0; l_i < n_i; l_i = l_i + 1) begin
                if (bk[(2*l_i+1)*KW +: KW] < bk[(2*l_i)*KW +: KW]) begin
                    bk[l_i*KW +: KW] = bk[(2*l_i+1)*KW +: KW];
                    bi[l_i*SB +: SB] = bi[(2*l_i+1)*SB +: SB];
                    bs[l_i*SB +: SB] = bs[(2*l_i+1)*SB +: SB];
                end else begin
                    bk[l_i*KW +: KW] = bk[(2*l_i)*KW +: KW];
                    bi[l_i*SB +: SB] = bi[(2*l_i)*SB +: SB];
                    bs[l_i*SB +: SB] = bs[(2*l_i)*SB +: SB];
                end
            end
        end
        m_found = ~bk[KW-1];
        m_t = bi[SB-1:0];
        m_s = bs[SB-1:0];
    end
    // the picked touch's cached slot is still free (one-hot select: no barrel shifter)
    reg m_fresh;
    always @* begin : c_fresh
        integer s_i;
        m_fresh = 1'b0;
        for (s_i = 0; s_i < MT; s_i = s_i + 1)
            m_fresh = m_fresh | (~sused_q[s_i] & (m_s == s_i[SB-1:0]));
    end

    // ---- lifts: lowest active unmatched slot whose hold-off expires --------------
    reg [MT-1:0] lift_mask;
    reg          l_found;
    reg [SB-1:0] l_s;
    always @* begin : c_lift
        integer s_i;
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
    always @* begin : c_new
        integer t_i, k_i;
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
    wire [SB-1:0] f_next = ({1'b0, f_s} == MT - 1) ? {SB{1'b0}} : f_s + 1'b1;

    // ---- update: lowest active slot neither matched, new nor updated yet -------------
    reg          u_found;
    reg [SB-1:0] u_s;
    always @* begin : c_upd
        integer s_i;
        u_found = |(act_q & ~sused_q);
        u_s = {SB{1'b0}};
        for (s_i = MT - 1; s_i >= 0; s_i = s_i - 1)
            if (act_q[s_i] && !sused_q[s_i]) u_s = s_i[SB-1:0];
    end

    // ---- slot RAM port (read and write at one address) and touch RAM read ------------
    reg  [SB-1:0]    sa;             // slot of this cycle
    always @* begin
        case (state_q)
            S_MATCH: sa = mv_s_q;
            S_LIFT:  sa = l_s;
            S_NEW:   sa = f_s;
            S_UPD:   sa = u_s;
            default: sa = mv_s_q;
        endcase
    end
    wire [SD_W-1:0]  srec  = smem[sa];
    wire [P_W-1:0]   s_px  = srec[SD_W-1 -: P_W];
    wire [P_W-1:0]   s_py  = srec[SD_W-P_W-1 -: P_W];
    wire [V_W-1:0]   s_vx  = srec[SD_W-2*P_W-1 -: V_W];
    wire [V_W-1:0]   s_vy  = srec[SD_W-2*P_W-V_W-1 -: V_W];
    wire [15:0]      s_lx  = srec[31:16];
    wire [15:0]      s_ly  = srec[15:0];
    reg  [GEN_W-1:0] s_gen;          // generation of slot sa (one-hot select)
    always @* begin : c_sgen
        integer s_i;
        s_gen = {GEN_W{1'b0}};
        for (s_i = 0; s_i < MT; s_i = s_i + 1)
            s_gen = s_gen | (gen_q[s_i*GEN_W +: GEN_W] & {GEN_W{sa == s_i[SB-1:0]}});
    end
    wire [GEN_W-1:0] f_gen = s_gen + 1'b1;

    wire [SB-1:0]    ta    = (state_q == S_NEW) ? n_t : mv_t_q;
    wire [TD_W-1:0]  trec  = tmem[ta];
    wire [15:0]      t_x   = trec[TD_W-1 -: 16];
    wire [15:0]      t_y   = trec[TD_W-17 -: 16];

    // matched pair: velocity / prediction update
    wire [V_W-1:0]   m_vx_new, m_vy_new;
    wire [P_W-1:0]   m_px_new, m_py_new;
    fmt_tracker_vel #(.VF(VF), .V_W(V_W), .P_W(P_W)) u_velx (
        .meas_i(t_x), .p_i(s_px), .v_i(s_vx),
        .shift_i(vel_shift_i), .vmax_i(max_speed_i), .v_o(m_vx_new), .p_o(m_px_new));
    fmt_tracker_vel #(.VF(VF), .V_W(V_W), .P_W(P_W)) u_vely (
        .meas_i(t_y), .p_i(s_py), .v_i(s_vy),
        .shift_i(vel_shift_i), .vmax_i(max_speed_i), .v_o(m_vy_new), .p_o(m_py_new));
    // unmatched slot in hold-off: p + v
    wire [P_W-1:0]   u_px  = s_px + {{(P_W-V_W){s_vx[V_W-1]}}, s_vx};
    wire [P_W-1:0]   u_py  = s_py + {{(P_W-V_W){s_vy[V_W-1]}}, s_vy};
    wire             u_en  = (state_q == S_UPD) && u_found;
    wire             n_en  = (state_q == S_NEW) && n_found && f_found;

    // slot write: move (mv_q, in MATCH), new, update
    reg              s_we;
    reg [SD_W-1:0]   s_wd;
    reg [P_W-1:0]    w_px, w_py;     // the written p: rounded into the prediction registers
    always @* begin
        s_we = 1'b0;
        w_px = u_px;
        w_py = u_py;
        s_wd = {u_px, u_py, s_vx, s_vy, s_lx, s_ly};
        if (state_q == S_MATCH) begin
            s_we = mv_q;
            w_px = m_px_new;
            w_py = m_py_new;
            s_wd = {m_px_new, m_py_new, m_vx_new, m_vy_new, t_x, t_y};
        end else if (state_q == S_NEW) begin
            s_we = n_en;
            w_px = {{(P_W-16-VF){1'b0}}, t_x, {VF{1'b0}}};
            w_py = {{(P_W-16-VF){1'b0}}, t_y, {VF{1'b0}}};
            s_wd = {w_px, w_py, {(2*V_W){1'b0}}, t_x, t_y};
        end else if (state_q == S_UPD) begin
            s_we = u_en;
        end
    end
    always @(posedge clk) begin
        if (s_we) smem[sa] <= s_wd;
    end

    // round half up, (p + 2^(VF-1)) >>> VF, then saturate to PR_W bits
    function [PR_W-1:0] pred_of;
        input [P_W-1:0] p;
        /* verilator lint_off UNUSEDSIGNAL */   // the low VF bits are the dropped fraction
        reg   [P_W-1:0] r;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            r = p + ({{(P_W-1){1'b0}}, 1'b1} << (VF - 1));
            if (r[P_W-1:VF+PR_W-1] == {(PI_W-PR_W+1){1'b0}} ||
                r[P_W-1:VF+PR_W-1] == {(PI_W-PR_W+1){1'b1}})
                pred_of = r[VF+PR_W-1:VF];
            else if (r[P_W-1])
                pred_of = {1'b1, {(PR_W-1){1'b0}}};
            else
                pred_of = {1'b0, {(PR_W-1){1'b1}}};
        end
    endfunction
    // the written p is registered and rounded into the prediction registers one cycle
    // later (off the velocity update's path); the last write lands in the cycle that
    // clears the frame, before the next frame's touches can arrive
    reg              pw_q;
    reg [SB-1:0]     pw_s_q;
    reg [P_W-1:0]    pw_x_q, pw_y_q;
    wire [PR_W-1:0]  w_prx = pred_of(pw_x_q);
    wire [PR_W-1:0]  w_pry = pred_of(pw_y_q);
    // the slot's miss counter: 0 on move / new, + 1 on update (shared incrementer)
    reg [HOLD_W-1:0] u_miss;
    always @* begin : c_umiss
        integer s_i;
        u_miss = {HOLD_W{1'b0}};
        for (s_i = 0; s_i < MT; s_i = s_i + 1)
            u_miss = u_miss | (miss_q[s_i*HOLD_W +: HOLD_W] & {HOLD_W{u_s == s_i[SB-1:0]}});
    end
    wire [HOLD_W-1:0] w_miss = (state_q == S_UPD) ? u_miss + 1'b1 : {HOLD_W{1'b0}};

    // ---- events ---------------------------------------------------------------------
    reg              gen_ev;           // an event is formed this cycle
    reg [1:0]        gen_type;
    always @* begin
        gen_ev = 1'b0;
        gen_type = T_MOVE;
        case (state_q)
            S_MATCH: gen_ev = mv_q;
            S_LIFT:  begin gen_ev = l_found;  gen_type = T_LIFT; end
            S_NEW:   begin gen_ev = n_en;     gen_type = T_NEW;  end
            default: ;
        endcase
    end
    wire [ID_W-1:0] gen_id   = {(state_q == S_NEW) ? f_gen : s_gen, sa};
    wire [TD_W-1:0] gen_data = (state_q == S_LIFT) ? {s_lx, s_ly, {(TD_W-32){1'b0}}} : trec;
    wire            frame_done = (state_q == S_NEW) && !n_found;

    // the cached key written this cycle: the row read on arrival or recomputed
    wire k_we = st_v_q | rc_q;

    always @(posedge clk) begin : s_main
        integer s_i, t_i;
        if (rst) begin
            state_q        <= S_IDLE;
            frame_q        <= {FRAME_W{1'b0}};
            tcnt_q         <= {TCW{1'b0}};
            st_v_q         <= 1'b0;
            st_t_q         <= {SB{1'b0}};
            kv_q           <= {MT{1'b0}};
            kd_q           <= {(MT*DW){1'b0}};
            ks_q           <= {(MT*SB){1'b0}};
            rc_q           <= 1'b0;
            rc_t_q         <= {SB{1'b0}};
            tused_q        <= {MT{1'b0}};
            sused_q        <= {MT{1'b0}};
            act_q          <= {MT{1'b0}};
            miss_q         <= {(MT*HOLD_W){1'b0}};
            prx_q          <= {(MT*PR_W){1'b0}};
            pry_q          <= {(MT*PR_W){1'b0}};
            gen_q          <= {(MT*GEN_W){1'b0}};
            pw_q           <= 1'b0;
            pw_s_q         <= {SB{1'b0}};
            pw_x_q         <= {P_W{1'b0}};
            pw_y_q         <= {P_W{1'b0}};
            next_slot_q    <= {SB{1'b0}};
            mv_q           <= 1'b0;
            mv_s_q         <= {SB{1'b0}};
            mv_t_q         <= {SB{1'b0}};
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
            st_v_q <= arrive;
            st_t_q <= wa_t;
            if (state_q == S_IDLE) begin
                if (tp_valid_i) begin
                    frame_q <= tp_frame_i;
                    if (tcnt_q < MT) tcnt_q <= tcnt_q + 1'b1;
                    else             drop_flag_o <= 1'b1;
                end
                if (tp_eof_i) begin
                    frame_q <= tp_frame_i;
                    state_q <= S_MATCH;
                end
            end else if (tp_valid_i || tp_eof_i) begin
                overrun_flag_o <= 1'b1;
            end

            // ---- cached per-touch minima -------------------------------------------
            for (t_i = 0; t_i < MT; t_i = t_i + 1) begin
                if (k_we && rr_t == t_i[SB-1:0]) begin
                    kv_q[t_i] <= r_found;
                    kd_q[t_i*DW +: DW] <= r_d;
                    ks_q[t_i*SB +: SB] <= r_s;
                end
            end

            // ---- slot registers written with the slot RAM ------------------------------
            for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
                if (s_we && sa == s_i[SB-1:0])
                    miss_q[s_i*HOLD_W +: HOLD_W] <= w_miss;
                if (pw_q && pw_s_q == s_i[SB-1:0]) begin
                    prx_q[s_i*PR_W +: PR_W] <= w_prx;
                    pry_q[s_i*PR_W +: PR_W] <= w_pry;
                end
            end
            pw_q   <= s_we;
            pw_s_q <= sa;
            pw_x_q <= w_px;
            pw_y_q <= w_py;

            // ---- matching / lifts / news / update -------------------------------------
            mv_q <= 1'b0;
            rc_q <= 1'b0;
            case (state_q)
                S_MATCH: begin
                    if (st_v_q || rc_q) begin
                        // a cached key is being written this cycle: pick next cycle
                    end else if (!m_found) begin
                        state_q <= S_LIFT;
                    end else if (m_fresh) begin
                        tused_q[m_t] <= 1'b1;
                        sused_q[m_s] <= 1'b1;
                        mv_q   <= 1'b1;
                        mv_s_q <= m_s;
                        mv_t_q <= m_t;
                    end else begin
                        rc_q   <= 1'b1;           // stale: recompute this touch's minimum
                        rc_t_q <= m_t;
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
                            act_q[f_s]   <= 1'b1;
                            for (s_i = 0; s_i < MT; s_i = s_i + 1)
                                if (f_s == s_i[SB-1:0]) gen_q[s_i*GEN_W +: GEN_W] <= f_gen;
                            sused_q[f_s] <= 1'b1;
                            next_slot_q  <= f_next;
                        end else begin
                            noslot_flag_o <= 1'b1;
                        end
                    end else begin
                        state_q <= S_UPD;
                    end
                end
                S_UPD: begin
                    if (u_found) begin
                        sused_q[u_s] <= 1'b1;     // updated
                    end else begin
                        tcnt_q  <= {TCW{1'b0}};
                        tused_q <= {MT{1'b0}};
                        sused_q <= {MT{1'b0}};
                        kv_q    <= {MT{1'b0}};
                        state_q <= S_IDLE;
                    end
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
