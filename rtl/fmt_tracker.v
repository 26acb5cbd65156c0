// fmt_tracker -- frame matching: stable contact IDs, new / move / lift events.
//
// Twin: sim/fmt/tracker.py (Tracker.step), bit-exact (same events, same order).  The
// cycle counts are modelled by tb/fmt_tracker (match_cycles, tail_latency).
//
// Contact table: MAX_TOUCHES slots.  In flip-flops (read by all slots in parallel):
// active flag, miss counter (frames since last seen), generation counter and the
// rounded prediction pred = (p + 2^(VF-1)) >>> VF per axis, clamped to PR_W = 18 bits
// signed, [-2^17, 2^17) (exact for the gate test: a prediction outside that range is,
// clamped or not, more than 65535 from any x in [0, 65535], so never a candidate).  In
// LUT RAMs (one word per slot; written before read, so not reset): p (signed,
// Q.(8+VF)), v (signed V_W bits, 2^-(8+VF) cells/frame), last measured x, y.
//
// Per frame (a pipeline: every step below is one register stage unless said):
//   COLLECT  touches arrive (tp_valid, any cycles; beyond MAX_TOUCHES dropped, sticky
//            drop_flag_o).  A1: the L1 distance of the touch to every slot's
//            prediction, D = |x - pred_x| + |y - pred_y|, saturated to 17 bits.  A2:
//            candidate = slot active and D <= the slot's gate (gate_q: max_jump_i
//            when the slot was matched or allocated, + gate_step_i, saturating at
//            0xFFFF, for every frame it was kept in hold-off: the distance a finger
//            can have moved), the row {cand, D} per slot written
//            to a LUT RAM.  R1..R_SB: the row read back and its minimum over the free
//            candidate slots, key (D, s), ties to the lower slot, one tree level per
//            stage, the last two levels in one (a 4:1 minimum; SB - 1 tree stages, none
//            at SB = 1); stage R_SB registers the key with its compare against every
//            queue entry, made from the root a cycle ahead (the result moves along with
//            its entry).  Then the key is inserted into a sorted queue.
//   MATCH    (after tp_eof; greedy nearest pairs, smallest (D, t, s) first) the queue
//            holds each touch's cached key sorted by (D, t), MAX_TOUCHES entries, insert and
//            pop in one cycle (registered compare bits, 4:1 select).  Cached keys
//            only grow as slots are taken, so each is a lower bound: per cycle, if the
//            head's slot is free and no key is in flight, the head IS the greedy pair:
//            it is assigned (a move) and every entry naming that slot marked stale; a
//            stale head is popped and its row minimum recomputed over the free slots
//            (R1..R_SB again, reinserted SB + 1 cycles later; several in flight, no
//            assignment meanwhile).  Empty queue, nothing in flight: MATCH ends.
//            The loop is only the head's compare-and-select: no search in the loop.
//   EV       from the cycle after MATCH ends: one lift per cycle (lowest slot first,
//            active, unmatched, tentative or miss + 1 >= hold_off_i), then one new
//            per cycle (unmatched touches at least on_thr_i strong, in arrival order;
//            the first free slot after the round-robin pointer; generation + 1).  No
//            free slot: the contact in hold-off seen longest ago (its last move or new
//            issued earliest: an age order of the slots, older_q[j][i] = slot j's last
//            move or new came before slot i's, set when a move or new is issued) is put
//            into the lift mask (one cycle without an issue), lifted in the next cycle
//            like any lift, and the new takes its slot; none in hold-off either:
//            dropped, sticky noslot_flag_o.  Every mask keeps its lowest set bit (the hold-off
//            mask its oldest slot: the next pick) and "not empty" in registers,
//            computed the cycle before.
//   Confirmation (confirm_i >= 2): a new slot is tentative (seen 1 frame); its moves
//            count frames seen and the one that makes confirm_i is reported as 'new';
//            until then its operations emit nothing, and it is lifted without an
//            event the first frame it is not matched (no hold-off).
//   UPD      then one slot per cycle in hold-off (active, neither matched nor new):
//            miss + 1, p += v; busy_o falls when the update pipeline has drained.
// Every move / lift / new / update is an operation: issued into a register, released
// (stage E1: LUT-RAM reads, the event, miss counter, tentative count) when the next
// operation is issued or the frame's events end, then fmt_tracker_vel E2..E4
// (velocity filter, e = (x << VF) - p; v = clamp(v + (e >>> vel_shift_i),
// +-max_speed_i); p = (x << VF) + v; p, v written) and E5 (the prediction rounded into
// its registers).  E1's event (if reported) waits in a hold register: it goes out when
// the frame's next reported event comes, or marked ev_last_o in the cycle after the
// events end (so a frame whose last operations report nothing still ends with
// ev_last_o on its last event).  No multiplier, no block RAM.
//
// Latency (tp_eof in cycle c, the frame's last touch in cycle a <= c; SB = 4 at 16
// slots): first MATCH decision in cycle d0 = max(c + 1, a + SB + 3); without stale
// pops MATCH ends m cycles later (m moves); l lifts and n news take one cycle each,
// an eviction one more (its lift is one of the l; in the frames that evict, add their
// number to l + n below: at most the number of touches, so the worst case stays);
// the last event is on the output in cycle d0 + m + l + n + 2 + e (e = 1 if l + n > 0:
// lifts and news start the cycle after MATCH ends, so that their masks and picks come
// from registers only; l and n count every lift and new operation, also the silent
// ones of tentative contacts), i.e. m + l + n + 8 + e cycles after tp_eof when the last
// touch came the cycle before (was m + 2k + l + n + d + 4 with k stale picks and d
// touches without a slot, which now cost nothing; + 1 since the event hold).
// Stale pops: 1 cycle each, and the round waits for the last recomputed key (SB + 1
// cycles).  Worst case (16 touches ranking 16 slots alike: 120 stale pops): MATCH 211,
// last event 219 cycles after tp_eof (was 260), busy 3 cycles more; with the 16 touch
// cycles, 238 of a frame's 768.  busy_o falls 3 cycles after the last event with no
// contact in hold-off, h + 4 with h.  A frame with no events emits nothing.  Touches of
// the next frame must not arrive before the tracker is idle again (overrun_flag_o;
// they are dropped).  tp_frame_i is sampled with every touch and with tp_eof.
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
    input  wire [15:0]           gate_step_i,      // L1 gate growth per frame missed (Q8.8)
    input  wire [HOLD_W-1:0]     hold_off_i,       // frames missing before lift (0 acts as 1)
    input  wire [3:0]            vel_shift_i,      // velocity filter gain 2^-S, S <= VF
    input  wire [V_W-2:0]        max_speed_i,      // |v| clamp per axis, 2^-(8+VF) cells/frame
    input  wire [HM_W-1:0]       on_thr_i,         // activation: a new contact needs this strength
    input  wire [2:0]            confirm_i,        // frames seen before a new contact's event (0 = 1)
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
    localparam NW    = KW + SB;              // tree node {invalid, D, slot}
    localparam RW    = MT * KW;              // distance-RAM row: {cand, D} per slot
    localparam TNN   = (MTP > 4) ? MTP - 4 : 1;  // 2:1 tree nodes in registers (none: 1 unused)
    localparam TD_W  = 16 + 16 + HM_W + 16 + 16 + 8 + 8;  // touch record width

    localparam [3:0] S_IDLE = 4'b0001, S_MATCH = 4'b0010, S_EV = 4'b0100, S_UPD = 4'b1000;
    localparam [1:0] T_NEW = 2'd0, T_MOVE = 2'd1, T_LIFT = 2'd2, T_UPD = 2'd3;

    // ---- functions ------------------------------------------------------------------------
    // smaller tree node, ties to a (the lower slot)
    function [NW-1:0] nmin;
        input [NW-1:0] a;
        input [NW-1:0] b;
        begin
            nmin = (b[NW-1:SB] < a[NW-1:SB]) ? b : a;
        end
    endfunction
    // smallest of four tree nodes, ties to the lowest (a, b, c, d = ascending slots):
    // the six compares side by side, then one 4:1 select
    function [NW-1:0] nmin4;
        input [NW-1:0] a;
        input [NW-1:0] b;
        input [NW-1:0] c;
        input [NW-1:0] d;
        reg ba, ca, da, cb, db, dc;        // xy: x sorts strictly before y
        begin
            ba = b[NW-1:SB] < a[NW-1:SB];
            ca = c[NW-1:SB] < a[NW-1:SB];
            da = d[NW-1:SB] < a[NW-1:SB];
            cb = c[NW-1:SB] < b[NW-1:SB];
            db = d[NW-1:SB] < b[NW-1:SB];
            dc = d[NW-1:SB] < c[NW-1:SB];
            if (!ba && !ca && !da)     nmin4 = a;
            else if (ba && !cb && !db) nmin4 = b;
            else if (ca && cb && !dc)  nmin4 = c;
            else                       nmin4 = d;
        end
    endfunction
    // index of a one-hot vector
    function [SB-1:0] enc;
        input [MT-1:0] oh;
        integer i;
        begin
            enc = {SB{1'b0}};
            for (i = 0; i < MT; i = i + 1)
                if (oh[i]) enc = enc | i[SB-1:0];
        end
    endfunction
    // the oldest slot of a mask by the age order (one-hot, 0 if none): in the mask, and
    // no slot of the mask seen before it
    function [MT-1:0] oldest;
        input [MT-1:0]    m;
        input [MT*MT-1:0] o;
        integer i, j;
        reg     b;
        begin
            for (i = 0; i < MT; i = i + 1) begin
                b = 1'b0;
                for (j = 0; j < MT; j = j + 1)
                    if (j != i) b = b | (m[j] & o[j*MT + i]);   // (the diagonal is unused)
                oldest[i] = m[i] & ~b;
            end
        end
    endfunction
    // lowest set bit (one-hot, 0 if none)
    function [MT-1:0] lowest;
        input [MT-1:0] m;
        begin
            lowest = m & (~m + 1'b1);
        end
    endfunction
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

    // ---- state ------------------------------------------------------------------------
    reg [3:0]           state_q;                  // one-hot: UPD, EV, MATCH, IDLE
    reg [FRAME_W-1:0]   frame_q;
    reg [TCW-1:0]       tcnt_q;                   // touches stored this frame
    reg [MT-1:0]        tval_q;                   // touch stored
    reg [MT-1:0]        tused_q;                  // touch matched
    reg [MT-1:0]        sused_q;                  // slot matched or newly allocated
    reg [MT-1:0]        act_q;                    // slot active
    reg [MT-1:0]        tstr_q;                   // touch at least on_thr_i strong (may start a contact)
    reg [MT-1:0]        tent_q;                   // slot tentative (not reported yet)
    reg [MT*3-1:0]      seen_q;                   // frames seen while tentative
    reg                 cf1_q;                    // confirm_i <= 1: news reported at once
    // the event hold: an event goes out when the frame's next reported event comes, or
    // flagged last in the cycle after the events end (fl_q)
    reg                 hev_v_q, fl_q;
    reg [ID_W-1:0]      hev_id_q;
    reg [1:0]           hev_typ_q;
    reg [TD_W-1:0]      hev_d_q;
    reg [MT*HOLD_W-1:0] miss_q;                   // frames since last seen
    reg [MT*16-1:0]     gate_q;                   // L1 match gate per slot (Q8.8)
    reg [MT-1:0]        lexp_q;                   // miss + 1 >= hold-off (lift if unmatched)
    reg [HOLD_W-1:0]    hm1_q;                    // max(hold_off, 1) - 1
    reg [MT*PR_W-1:0]   prx_q, pry_q;             // rounded, saturated predictions
    reg [MT*GEN_W-1:0]  gen_q;                    // generation counters
    reg [MT-1:0]        therm_q;                  // slots after the last allocated one
    reg [MT-1:0]        lm_q;                     // lifts to issue
    reg [MT-1:0]        um_q;                     // unmatched touches (news to issue)
    reg [MT-1:0]        fm_q;                     // free slots
    reg [MT-1:0]        src_q;                    // free slots after the pointer, else fm_q
    reg [MT-1:0]        upm_q;                    // hold-off updates to issue
    reg [MT-1:0]        ho_q;                     // contacts in hold-off (EV: may be evicted)
    reg [MT*MT-1:0]     older_q;                  // [j*MT + i]: slot j seen before slot i
    reg [MT-1:0]        l_pick_q, u_pick_q, f_pick_q, p_pick_q;   // lowest bits (one-hot)
    reg [MT-1:0]        o_pick_q;                 // the oldest contact in hold-off (one-hot)
    reg                 l_any_q, u_any_q, f_any_q, p_any_q, o_any_q; // masks not empty
    // arrival: A1 distances, A2 gate test and row write
    reg                 a1_v_q;
    reg                 a1_str_q;                 // the touch is at least on_thr_i strong
    reg [SB-1:0]        a1_t_q;
    reg [MT*KW-1:0]     dq_q;                     // {D >= 2^16, D mod 2^16} per slot
    // row minimum: request (stage 0), tree stages 1..SB-1 (stage k < SB - 1 holds
    // MTP >> k nodes from node MTP - (MTP >> (k - 1)); stage SB - 1 the root, the last two
    // levels in one), key (stage SB: the root and its compares with the queue)
    reg [SB:0]          rv_q;                     // stage valid
    reg [(SB+1)*SB-1:0] rt_q;                     // stage touch index
    reg [TNN*NW-1:0]    tr_q;                     // 2:1 tree nodes {invalid, D, slot}
    reg [NW-1:0]        key_q;                    // the key {invalid, D, slot}
    reg [MT-1:0]        kc_q;                     // the key sorts before entry i (D, t)
    // sorted key queue (entry 0 = head)
    reg [MT-1:0]        qv_q, qst_q;              // valid, stale (slot taken since)
    reg [MT*DW-1:0]     qd_q;
    reg [MT*SB-1:0]     qt_q, qs_q;
    // operation register (stage E1 when released) and the update pipeline E2..E5
    reg                 op_v_q;
    reg [1:0]           op_typ_q;
    reg                 op_vis_q;                     // its event is reported
    reg                 op_tnt_q;                     // a tentative slot's move
    reg                 op_cnf_q;                     // ... that confirms it
    reg [2:0]           op_seen_q;                    // ... its frames seen then
    reg [1:0]           op_etyp_q;                    // event type (a confirming move: new)
    reg [SB-1:0]        op_t_q, op_s_q;               // touch, slot
    reg [MT-1:0]        op_so_q;                      // slot (one-hot)
    reg                 e2_v_q, e3_v_q, e4_v_q;
    reg [1:0]           e2_typ_q, e3_typ_q, e4_typ_q;
    reg [SB-1:0]        e2_s_q, e3_s_q, e4_s_q;
    reg                 pw_q;
    reg [SB-1:0]        pw_s_q;
    reg [P_W-1:0]       pw_x_q, pw_y_q;

    assign busy_o = ~state_q[0];

    // ---- LUT RAMs (asynchronous read, no reset: a word is written before it is read) --
    reg [RW-1:0]     dmem [0:MTP-1];     // distance rows (A2 write, R1 read)
    reg [TD_W-1:0]   tmem [0:MTP-1];     // touch records (arrival write, E1 read)
    reg [2*P_W-1:0]  pmem [0:MTP-1];     // slot p {x, y} (E4 write, E1 read)
    reg [2*V_W-1:0]  vmem [0:MTP-1];     // slot v {x, y} (E4 write, E1 read)
    reg [31:0]       lmem [0:MTP-1];     // slot last measured {x, y} (E1 read / write)

    wire            arrive = state_q[0] && tp_valid_i && (tcnt_q < MT);
    wire [SB-1:0]   wa_t   = tcnt_q[SB-1:0];      // < MT when arrive

    always @(posedge clk) begin
        if (arrive)
            tmem[wa_t] <= {tp_x_i, tp_y_i, tp_strength_i, tp_axis_major_i, tp_axis_minor_i,
                           tp_angle_i, tp_flags_i};
    end

    // ---- A1: L1 distance of the arriving touch to every slot's prediction --------------
    reg [MT*KW-1:0]     dsat;
    reg signed [PR_W:0] ddx, ddy;
    reg [PR_W:0]        dsum;
    always @* begin : c_dist
        integer s_i;
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            ddx = $signed({{(PR_W-15){1'b0}}, tp_x_i}) -
                  $signed({prx_q[s_i*PR_W+PR_W-1], prx_q[s_i*PR_W +: PR_W]});
            ddy = $signed({{(PR_W-15){1'b0}}, tp_y_i}) -
                  $signed({pry_q[s_i*PR_W+PR_W-1], pry_q[s_i*PR_W +: PR_W]});
            // |ddx|, |ddy| < 2^PR_W: the sum fits PR_W + 1 bits
            dsum = {1'b0, ddx[PR_W-1:0] ^ {PR_W{ddx[PR_W]}}} + {{PR_W{1'b0}}, ddx[PR_W]} +
                   {1'b0, ddy[PR_W-1:0] ^ {PR_W{ddy[PR_W]}}} + {{PR_W{1'b0}}, ddy[PR_W]};
            dsat[s_i*KW +: KW] = {|dsum[PR_W:DW], dsum[DW-1:0]};
        end
    end

    // ---- A2: candidate = slot active and D <= gate; row written to the distance RAM -----
    // D > gate is the carry of D + ~gate
    reg [RW-1:0] drow;
    reg [DW:0]   dgt;
    always @* begin : c_drow
        integer s_i;
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            dgt = {1'b0, dq_q[s_i*KW +: DW]} + {1'b0, ~gate_q[s_i*16 +: 16]};
            drow[s_i*KW +: KW] = {act_q[s_i] && !dq_q[s_i*KW+DW] && !dgt[DW],
                                  dq_q[s_i*KW +: DW]};
        end
    end
    always @(posedge clk) begin
        if (a1_v_q) dmem[a1_t_q] <= drow;
    end

    // ---- row minimum over the free candidate slots, one tree level per stage -----------
    // (ties to the lower slot; the leaves are the row read in stage 1; the last two
    // levels in one stage, a 4:1 minimum; SB = 1: the one level is combinational)
    wire [SB-1:0]    rq_t = rt_q[0 +: SB];
    wire [RW-1:0]    rrow = dmem[rq_t];
    reg  [MTP*NW-1:0] lf;
    reg  [TNN*NW-1:0] tr_d;
    always @* begin : c_tree
        integer s_i, k, l;
        for (s_i = 0; s_i < MTP; s_i = s_i + 1) begin
            if (s_i < MT)
                lf[s_i*NW +: NW] = {~(rrow[s_i*KW+DW] & ~sused_q[s_i]), rrow[s_i*KW +: DW],
                                    s_i[SB-1:0]};
            else
                lf[s_i*NW +: NW] = {{KW{1'b1}}, s_i[SB-1:0]};
        end
        tr_d = {(TNN*NW){1'b0}};
        if (SB > 2)
            for (l = 0; l < MTP / 2; l = l + 1)
                tr_d[l*NW +: NW] = nmin(lf[(2*l)*NW +: NW], lf[(2*l+1)*NW +: NW]);
        // stage k - 1 starts at node MTP - (MTP >> (k - 2)), stage k at MTP - (MTP >> (k - 1))
        for (k = 2; k <= SB - 2; k = k + 1)
            for (l = 0; l < (MTP >> k); l = l + 1)
                tr_d[(MTP-(MTP>>(k-1))+l)*NW +: NW] =
                    nmin(tr_q[(MTP-(MTP>>(k-2))+2*l)*NW +: NW],
                         tr_q[(MTP-(MTP>>(k-2))+2*l+1)*NW +: NW]);
    end
    // the root (stage SB - 1) and its touch
    wire [NW-1:0] root;
    generate
        if (SB > 2) begin : g_root
            wire [NW-1:0] root_d = nmin4(tr_q[(MTP-8)*NW +: NW], tr_q[(MTP-7)*NW +: NW],
                                         tr_q[(MTP-6)*NW +: NW], tr_q[(MTP-5)*NW +: NW]);
            reg  [NW-1:0] rootq_q;
            assign root = rootq_q;
            always @(posedge clk) rootq_q <= root_d;
        end else if (SB == 2) begin : g_root2
            wire [NW-1:0] root_d = nmin4(lf[0 +: NW], lf[NW +: NW], lf[2*NW +: NW],
                                         lf[3*NW +: NW]);
            reg  [NW-1:0] rootq_q;
            assign root = rootq_q;
            always @(posedge clk) rootq_q <= root_d;
        end else begin : g_root1
            assign root = nmin(lf[0 +: NW], lf[NW +: NW]);
        end
    endgenerate
    wire [SB-1:0] root_t  = rt_q[(SB-1)*SB +: SB];
    wire [DW-1:0] key_d_q = key_q[NW-2 -: DW];
    wire [SB-1:0] key_s_q = key_q[SB-1:0];
    wire [SB-1:0] key_t_q = rt_q[SB*SB +: SB];

    // ---- sorted queue of the touches' keys (D, t) ---------------------------------------
    // inflight_q: a key is on its way (A2 or a tree stage valid this cycle)
    reg  inflight_q;
    wire in_match = state_q[1];
    // (keep: q_asg and q_pop each one LUT of the same four registers, which their many
    // users read, so the mapper builds neither from the other nor in a chain of gates)
    (* keep *) wire q_asg, q_pop;
    assign q_asg  = in_match & qv_q[0] & ~qst_q[0] & ~inflight_q; // head is the greedy pair
    wire q_stale  = in_match & qv_q[0] & qst_q[0];                // head: recompute its key
    assign q_pop  = in_match & qv_q[0] & (qst_q[0] | ~inflight_q); // = q_asg | q_stale
    wire m_done   = in_match & ~qv_q[0] & ~inflight_q;            // no candidate pair left
    wire key_ins  = rv_q[SB] & ~key_q[NW-1];
    wire [SB-1:0] h_t = qt_q[0 +: SB];
    wire [SB-1:0] h_s = qs_q[0 +: SB];

    // The key's compare with every entry is made a cycle ahead, from the root (stage
    // SB - 1) against the entries and the key inserted in that cycle; each result moves
    // along with its entry (the same 4:1 select, c_qnext) into kc_q.  kc_q is exact
    // whenever the key is.
    reg  [MT+1:0] kc_n;            // now: the root before entry j - 1 (ends: don't care)
    reg           kc_k;            // now: the root before the key inserted now
    always @* begin : c_qcmp
        integer i;
        kc_n[0] = 1'b1;
        for (i = 0; i < MT; i = i + 1)
            kc_n[i+1] = {root[NW-2 -: DW], root_t} < {qd_q[i*DW +: DW], qt_q[i*SB +: SB]};
        kc_n[MT+1] = 1'b1;
        kc_k = {root[NW-2 -: DW], root_t} < {key_d_q, key_t_q};
    end

    // xl[j]: the key sorts before entry j - 1 (or that entry is empty); xl[0] = 0
    reg  [MT+1:0]       xl;
    always @* begin : c_qlt
        integer i;
        xl[0] = 1'b0;
        for (i = 0; i < MT; i = i + 1)
            xl[i+1] = ~qv_q[i] | kc_q[i];
        xl[MT+1] = 1'b1;
    end
    // next state of entry i, a 4:1 select per entry: 0 keep, 1 entry i + 1 (a pop),
    // 2 entry i - 1 (shifted down by an insert), 3 the inserted key.  An insert goes
    // before the first later-sorting entry; a pop and an insert may come together.
    localparam QE = 2 + DW + 2 * SB;        // entry {valid, stale, D, t, s}
    wire [(MT+2)*QE-1:0] xq;                // entries with an empty one at each end
    genvar gq;
    assign xq[0 +: QE]         = {QE{1'b0}};
    assign xq[(MT+1)*QE +: QE] = {QE{1'b0}};
    generate
        for (gq = 0; gq < MT; gq = gq + 1) begin : g_xq
            assign xq[(gq+1)*QE +: QE] = {qv_q[gq], qst_q[gq], qd_q[gq*DW +: DW],
                                          qt_q[gq*SB +: SB], qs_q[gq*SB +: SB]};
        end
    endgenerate
    wire [QE-1:0] kq = {1'b1, 1'b0, key_d_q, key_t_q, key_s_q};
    reg  [MT*2-1:0]  qsel;
    reg  [MT-1:0]    qeq;                   // entry i + 1 holds the slot assigned now
    always @* begin : c_qsel
        integer i;
        reg l_s, l_m;
        for (i = 0; i < MT; i = i + 1) begin
            l_s = q_pop ? xl[i+2] : xl[i+1];
            l_m = q_pop ? ((i == 0) ? 1'b0 : xl[i+1]) : xl[i];
            if (key_ins && l_s && l_m)
                qsel[2*i +: 2] = q_pop ? 2'd0 : 2'd2;
            else if (key_ins && l_s)
                qsel[2*i +: 2] = 2'd3;
            else
                qsel[2*i +: 2] = q_pop ? 2'd1 : 2'd0;
            qeq[i] = xq[(i+2)*QE+QE-1] && (xq[(i+2)*QE +: SB] == h_s);
        end
    end
    reg [MT-1:0]    qv_d, qst_d, kc_d;
    reg [MT*DW-1:0] qd_d;
    reg [MT*SB-1:0] qt_d, qs_d;
    always @* begin : c_qnext
        integer i;
        reg [QE-1:0] e;
        for (i = 0; i < MT; i = i + 1) begin
            case (qsel[2*i +: 2])
                2'd0: begin
                    e = xq[(i+1)*QE +: QE];
                    kc_d[i] = kc_n[i+1];
                end
                2'd1: begin
                    e = xq[(i+2)*QE +: QE];
                    kc_d[i] = kc_n[i+2];
                end
                2'd2: begin
                    e = xq[i*QE +: QE];
                    kc_d[i] = kc_n[i];
                end
                default: begin
                    e = kq;
                    kc_d[i] = kc_k;
                end
            endcase
            {qv_d[i], qst_d[i], qd_d[i*DW +: DW], qt_d[i*SB +: SB], qs_d[i*SB +: SB]} = e;
            qst_d[i] = e[QE-2] | (q_asg & qeq[i]);   // an assignment pops: e is entry i + 1
        end
    end

    // ---- issue: moves (MATCH), lifts and news (EV), hold-off updates (UPD) ------------
    // Each mask has its lowest set bit (the next pick, one-hot) and "not empty" in
    // registers, computed the cycle before: the issue is a select of registers.
    wire [MT-1:0] one     = {{(MT-1){1'b0}}, 1'b1};
    wire [MT-1:0] asg_s   = q_asg ? (one << h_s) : {MT{1'b0}};
    wire [MT-1:0] asg_t   = q_asg ? (one << h_t) : {MT{1'b0}};
    wire [MT-1:0] sused_n = sused_q | asg_s;
    wire [MT-1:0] tused_n = tused_q | asg_t;
    wire [MT-1:0] tval_n  = tval_q | (arrive ? (one << wa_t) : {MT{1'b0}});
    // the activation compare is registered with the touch (A1): the news are decided
    // after MATCH, long after
    wire [MT-1:0] tstr_n  = tstr_q | ((a1_v_q && a1_str_q) ? (one << a1_t_q) : {MT{1'b0}});

    // The masks of IDLE and MATCH from registers (their _b forms): exact in the cycle
    // MATCH ends (m_done: no assignment, no arrival and nothing in A1 then), and held
    // into EV.  In the m_done cycle itself ev_done reads their "not empty" bits from
    // these forms, not from the registered ones, so no assignment of the cycle before
    // has to reach the any-bits (the assignment stays off these paths).
    wire [MT-1:0] lm_b = act_q & ~sused_q & (lexp_q | tent_q);
    wire [MT-1:0] ho_b = act_q & ~sused_q & ~(lexp_q | tent_q);
    wire [MT-1:0] um_b = tval_q & tstr_q & ~tused_q;

    // lifts and news issue from the cycle after MATCH ends (EV), so the masks and their
    // picks update from registers only; a frame with none ends in the m_done cycle
    wire          iss_lift = state_q[2] & l_any_q;
    wire          iss_new  = state_q[2] & ~l_any_q & u_any_q & f_any_q;
    // no free slot for the next new: the oldest contact in hold-off goes into the lift
    // mask (this cycle issues nothing; its lift is the next)
    wire          evict    = state_q[2] & ~l_any_q & u_any_q & ~f_any_q & o_any_q;
    wire          u_any_m  = |um_b;        // (u_any_q's value in EV, read in m_done)
    wire          ev_done  = (m_done & ~(|lm_b) & ~(u_any_m & (f_any_q | (|ho_b))))
                           | (state_q[2] & ~l_any_q & ~(u_any_q & (f_any_q | o_any_q)));
    wire          iss_upd  = state_q[3] & p_any_q;
    wire          iss      = q_asg | iss_lift | iss_new | iss_upd;
    wire          drained  = ~op_v_q & ~e2_v_q & ~e3_v_q & ~e4_v_q;

    // next masks and their picks
    reg  [MT-1:0] lm_d, um_d, fm_d, src_d, upm_d, hm_d, ho_d;
    always @* begin
        lm_d  = lm_q;
        um_d  = um_q;
        fm_d  = fm_q;
        src_d = src_q;
        upm_d = upm_q;
        hm_d  = src_q;
        ho_d  = ho_q;
        if (state_q[0] || state_q[1]) begin
            // shadows of the pending lifts and news (above)
            lm_d  = lm_b;
            ho_d  = ho_b;
            um_d  = um_b;
            fm_d  = ~act_q;
            hm_d  = ~act_q & therm_q;
            src_d = (|hm_d) ? hm_d : fm_d;
        end else if (iss_lift) begin
            // the lifted slot is free for the news
            lm_d  = lm_q & ~l_pick_q;
            fm_d  = fm_q | l_pick_q;
            hm_d  = fm_d & therm_q;
            src_d = (|hm_d) ? hm_d : fm_d;
        end else if (iss_new) begin
            // src: free slots after the last pick (from the pointer), else all free slots
            um_d  = um_q & ~u_pick_q;
            fm_d  = fm_q & ~f_pick_q;
            hm_d  = src_q & ~f_pick_q;
            src_d = (|hm_d) ? hm_d : fm_d;
        end
        // an eviction: the oldest contact in hold-off is the next lift (lm_q is empty)
        if (evict) begin
            lm_d = o_pick_q;
            ho_d = ho_q & ~o_pick_q;
        end
        // hold-off updates: tracked from the registers until UPD (act_q and sused_q are
        // final in the ev_done cycle, which issues nothing), then one pick per update
        if (!state_q[3])
            upm_d = act_q & ~sused_q;
        else if (iss_upd)
            upm_d = upm_q & ~p_pick_q;
    end

    // confirmation, decided when an operation is issued (the slot's tentative state then:
    // a lift and a new of the same slot may follow each other, never two operations of
    // one slot otherwise): a tentative slot's move counts one more frame seen and is
    // reported as 'new' when that makes confirm_i, else not at all; a tentative slot's
    // lift is not reported; a new is reported only with confirmation off (cf1_q)
    // Each slot's count after one more frame and its confirmation are formed beside the
    // queue (from registers), and the head's slot then picks them with one mux (padded
    // to 2^SB slots, MTP): the select does not wait on the increment and the compare.
    reg  [MTP*5-1:0] sc_all;              // per slot {tent, conf, seen + 1 (saturating)}
    always @* begin : c_sconf
        integer s_i;
        reg [2:0] s1;
        sc_all = {(MTP*5){1'b0}};
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            s1 = (seen_q[s_i*3 +: 3] == 3'd7) ? 3'd7 : seen_q[s_i*3 +: 3] + 1'b1;
            sc_all[s_i*5 +: 5] = {tent_q[s_i], s1 >= confirm_i, s1};
        end
    end
    wire [4:0]    h_sc    = sc_all[h_s*5 +: 5];  // the head's slot
    wire          h_tent  = h_sc[4];             // tentative
    wire          h_conf  = h_sc[3];             // one more frame confirms it
    wire [2:0]    h_seen1 = h_sc[2:0];
    wire          l_tent  = |(tent_q & l_pick_q);

    // the issued operation: the four issue conditions exclude each other (MATCH, EV with
    // a lift pending or not, UPD), so each field is an AND-OR of its four sources
    wire [1:0]    iss_typ = {iss_lift | iss_upd, q_asg | iss_upd};   // T_MOVE 1, T_LIFT 2, T_UPD 3
    wire [SB-1:0] iss_s   = ({SB{q_asg}} & h_s) | ({SB{iss_lift}} & enc(l_pick_q)) |
                            ({SB{iss_new}} & enc(f_pick_q)) | ({SB{iss_upd}} & enc(p_pick_q));
    wire [MT-1:0] iss_so  = asg_s | ({MT{iss_lift}} & l_pick_q) | ({MT{iss_new}} & f_pick_q) |
                            ({MT{iss_upd}} & p_pick_q);
    // the slot a move or a new is issued for: it becomes the youngest in the age order
    wire [MT-1:0] seen_so = asg_s | ({MT{iss_new}} & f_pick_q);
    wire [SB-1:0] iss_t   = ({SB{q_asg}} & h_t) | ({SB{iss_new}} & enc(u_pick_q));

    // the held operation goes on when the next one is issued or the frame's events end
    // (in EV and UPD every cycle; in MATCH with an assignment or at the end)
    wire op_go = op_v_q & (~state_q[1] | (~inflight_q & ~(qv_q[0] & qst_q[0])));

    // ---- E1: the released operation reads its records; event out ------------------------
    wire [SB-1:0]    op_t  = op_t_q;
    wire [SB-1:0]    op_s  = op_s_q;
    wire [TD_W-1:0]  trec  = tmem[op_t];
    wire [15:0]      t_x   = trec[TD_W-1 -: 16];
    wire [15:0]      t_y   = trec[TD_W-17 -: 16];
    wire [2*P_W-1:0] prec  = pmem[op_s];
    wire [2*V_W-1:0] vrec  = vmem[op_s];
    wire [31:0]      lrec  = lmem[op_s];
    reg  [GEN_W-1:0] e1_gen;          // one-hot selects
    reg  [HOLD_W-1:0] e1_miss;
    reg  [15:0]      e1_gate;
    always @* begin : c_e1sel
        integer s_i;
        e1_gen  = {GEN_W{1'b0}};
        e1_miss = {HOLD_W{1'b0}};
        e1_gate = 16'd0;
        for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
            e1_gen  = e1_gen  | (gen_q[s_i*GEN_W +: GEN_W]   & {GEN_W{op_so_q[s_i]}});
            e1_miss = e1_miss | (miss_q[s_i*HOLD_W +: HOLD_W] & {HOLD_W{op_so_q[s_i]}});
            e1_gate = e1_gate | (gate_q[s_i*16 +: 16]         & {16{op_so_q[s_i]}});
        end
    end
    // the slot's new gate, written in E2: max_jump_i for a move or a new, the old gate +
    // gate_step_i (saturating) for a hold-off update; E1 registers the operand
    reg  [15:0]      e2_g_q;
    reg              e2_up_q;
    wire [16:0]      e2_gs = {1'b0, e2_g_q} + {1'b0, gate_step_i};
    wire [15:0]      e2_gn = !e2_up_q ? e2_g_q : (e2_gs[16] ? 16'hFFFF : e2_gs[15:0]);
    wire             e1_ev = op_go & op_vis_q;
    always @(posedge clk) begin
        if (op_go && (op_typ_q == T_MOVE || op_typ_q == T_NEW))
            lmem[op_s] <= {t_x, t_y};
    end

    // ---- E2..E4: velocity / prediction update (x and y) ----------------------------------
    wire [P_W-1:0] np_x, np_y;
    wire [V_W-1:0] nv_x, nv_y;
    fmt_tracker_vel #(.VF(VF), .V_W(V_W), .P_W(P_W)) u_velx (
        .clk(clk), .typ_i(op_typ_q), .meas_i(t_x), .p_i(prec[2*P_W-1 -: P_W]),
        .v_i(vrec[2*V_W-1 -: V_W]), .shift_i(vel_shift_i), .vmax_i(max_speed_i),
        .p_o(np_x), .v_o(nv_x));
    fmt_tracker_vel #(.VF(VF), .V_W(V_W), .P_W(P_W)) u_vely (
        .clk(clk), .typ_i(op_typ_q), .meas_i(t_y), .p_i(prec[P_W-1:0]),
        .v_i(vrec[V_W-1:0]), .shift_i(vel_shift_i), .vmax_i(max_speed_i),
        .p_o(np_y), .v_o(nv_y));
    always @(posedge clk) begin
        if (e4_v_q && e4_typ_q != T_LIFT)
            pmem[e4_s_q] <= {np_x, np_y};
        if (e4_v_q && (e4_typ_q == T_MOVE || e4_typ_q == T_NEW))
            vmem[e4_s_q] <= {nv_x, nv_y};
    end
    // E5: the written p rounded into the prediction registers
    wire [PR_W-1:0] w_prx = pred_of(pw_x_q);
    wire [PR_W-1:0] w_pry = pred_of(pw_y_q);

    always @(posedge clk) begin : s_main
        integer s_i, s_j;
        if (rst) begin
            state_q        <= S_IDLE;
            frame_q        <= {FRAME_W{1'b0}};
            tcnt_q         <= {TCW{1'b0}};
            tval_q         <= {MT{1'b0}};
            tused_q        <= {MT{1'b0}};
            sused_q        <= {MT{1'b0}};
            act_q          <= {MT{1'b0}};
            tstr_q         <= {MT{1'b0}};
            tent_q         <= {MT{1'b0}};
            seen_q         <= {(MT*3){1'b0}};
            cf1_q          <= 1'b1;
            hev_v_q        <= 1'b0;
            fl_q           <= 1'b0;
            hev_id_q       <= {ID_W{1'b0}};
            hev_typ_q      <= 2'd0;
            hev_d_q        <= {TD_W{1'b0}};
            miss_q         <= {(MT*HOLD_W){1'b0}};
            gate_q         <= {(MT*16){1'b0}};
            e2_g_q         <= 16'd0;
            e2_up_q        <= 1'b0;
            lexp_q         <= {MT{1'b0}};
            hm1_q          <= {HOLD_W{1'b0}};
            prx_q          <= {(MT*PR_W){1'b0}};
            pry_q          <= {(MT*PR_W){1'b0}};
            gen_q          <= {(MT*GEN_W){1'b0}};
            therm_q        <= {MT{1'b1}};
            lm_q           <= {MT{1'b0}};
            um_q           <= {MT{1'b0}};
            fm_q           <= {MT{1'b0}};
            src_q          <= {MT{1'b0}};
            upm_q          <= {MT{1'b0}};
            l_pick_q       <= {MT{1'b0}};
            o_pick_q       <= {MT{1'b0}};
            ho_q           <= {MT{1'b0}};
            o_any_q        <= 1'b0;
            u_pick_q       <= {MT{1'b0}};
            f_pick_q       <= {MT{1'b0}};
            p_pick_q       <= {MT{1'b0}};
            l_any_q        <= 1'b0;
            u_any_q        <= 1'b0;
            f_any_q        <= 1'b0;
            p_any_q        <= 1'b0;
            inflight_q     <= 1'b0;
            a1_v_q         <= 1'b0;
            a1_str_q       <= 1'b0;
            a1_t_q         <= {SB{1'b0}};
            dq_q           <= {(MT*KW){1'b0}};
            rv_q           <= {(SB+1){1'b0}};
            rt_q           <= {((SB+1)*SB){1'b0}};
            tr_q           <= {(TNN*NW){1'b0}};
            qv_q           <= {MT{1'b0}};
            qst_q          <= {MT{1'b0}};
            qd_q           <= {(MT*DW){1'b0}};
            qt_q           <= {(MT*SB){1'b0}};
            qs_q           <= {(MT*SB){1'b0}};
            kc_q           <= {MT{1'b0}};
            key_q          <= {1'b1, {(NW-1){1'b0}}};
            op_v_q         <= 1'b0;
            op_typ_q       <= T_NEW;
            op_vis_q       <= 1'b0;
            op_tnt_q       <= 1'b0;
            op_cnf_q       <= 1'b0;
            op_seen_q      <= 3'd0;
            op_etyp_q      <= T_NEW;
            op_t_q         <= {SB{1'b0}};
            op_s_q         <= {SB{1'b0}};
            op_so_q        <= {MT{1'b0}};
            e2_v_q         <= 1'b0;
            e3_v_q         <= 1'b0;
            e4_v_q         <= 1'b0;
            e2_typ_q       <= T_NEW;
            e3_typ_q       <= T_NEW;
            e4_typ_q       <= T_NEW;
            e2_s_q         <= {SB{1'b0}};
            e3_s_q         <= {SB{1'b0}};
            e4_s_q         <= {SB{1'b0}};
            pw_q           <= 1'b0;
            pw_s_q         <= {SB{1'b0}};
            pw_x_q         <= {P_W{1'b0}};
            pw_y_q         <= {P_W{1'b0}};
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
            if (state_q[0]) begin
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
            tval_q <= tval_n;
            tstr_q <= tstr_n;
            cf1_q  <= (confirm_i <= 3'd1);
            a1_v_q <= arrive;
            a1_str_q <= (tp_strength_i >= on_thr_i);
            a1_t_q <= wa_t;
            dq_q   <= dsat;

            // ---- per-slot flags (settle long before they are used) ---------------------
            hm1_q <= (hold_off_i == {HOLD_W{1'b0}}) ? {HOLD_W{1'b0}} : hold_off_i - 1'b1;
            for (s_i = 0; s_i < MT; s_i = s_i + 1) begin
                lexp_q[s_i] <= (miss_q[s_i*HOLD_W +: HOLD_W] >= hm1_q);
            end

            // ---- row minimum pipeline ------------------------------------------------
            rv_q <= {rv_q[SB-1:0], a1_v_q | q_stale};
            rt_q <= {rt_q[SB*SB-1:0], q_stale ? h_t : a1_t_q};
            tr_q <= tr_d;

            // ---- queue ---------------------------------------------------------------
            qv_q  <= qv_d;
            qst_q <= qst_d;
            qd_q  <= qd_d;
            qt_q  <= qt_d;
            qs_q  <= qs_d;
            kc_q  <= kc_d;
            key_q <= root;

            inflight_q <= arrive | a1_v_q | q_stale | (|rv_q[SB-1:0]);

            // ---- match: the greedy pair -----------------------------------------------
            if (q_asg) begin
                sused_q <= sused_n;
                tused_q <= tused_n;
            end

            // ---- masks and their next picks ------------------------------------------
            lm_q     <= lm_d;
            um_q     <= um_d;
            fm_q     <= fm_d;
            src_q    <= src_d;
            upm_q    <= upm_d;
            ho_q     <= ho_d;
            o_pick_q <= oldest(ho_d, older_q);
            o_any_q  <= |ho_d;
            l_pick_q <= lowest(lm_d);
            u_pick_q <= lowest(um_d);
            f_pick_q <= lowest(src_d);
            p_pick_q <= lowest(upm_d);
            l_any_q  <= |lm_d;
            u_any_q  <= |um_d;
            f_any_q  <= |fm_d;
            p_any_q  <= |upm_d;

            // ---- lifts, then news (first free slot from the round-robin pointer) --------
            if (iss_lift)
                act_q <= act_q & ~l_pick_q;
            // the age order (no reset: every pair of slots in hold-off has been set by
            // their moves or news since the reset)
            for (s_i = 0; s_i < MT; s_i = s_i + 1)
                for (s_j = 0; s_j < MT; s_j = s_j + 1)
                    if (seen_so[s_i])      older_q[s_j*MT + s_i] <= 1'b1;   // all before s_i
                    else if (seen_so[s_j]) older_q[s_j*MT + s_i] <= 1'b0;   // s_j the youngest
            if (iss_new) begin
                act_q   <= act_q | f_pick_q;
                sused_q <= sused_q | f_pick_q;
                therm_q <= ~(f_pick_q | (f_pick_q - 1'b1));
                for (s_i = 0; s_i < MT; s_i = s_i + 1)
                    if (f_pick_q[s_i]) begin
                        gen_q[s_i*GEN_W +: GEN_W] <= gen_q[s_i*GEN_W +: GEN_W] + 1'b1;
                        tent_q[s_i]               <= ~cf1_q;
                        seen_q[s_i*3 +: 3]        <= 3'd1;
                    end
            end
            if (m_done) state_q <= S_EV;
            if (ev_done) begin
                if (state_q[2] ? u_any_q : u_any_m) noslot_flag_o <= 1'b1;
                state_q <= S_UPD;
            end
            if (state_q[3] && !p_any_q && drained) begin
                tcnt_q  <= {TCW{1'b0}};
                tval_q  <= {MT{1'b0}};
                tstr_q  <= {MT{1'b0}};
                tused_q <= {MT{1'b0}};
                sused_q <= {MT{1'b0}};
                state_q <= S_IDLE;
            end

            // ---- operation register ------------------------------------------------------
            if (iss) begin
                op_v_q    <= 1'b1;
                op_tnt_q  <= q_asg & h_tent;
                op_cnf_q  <= h_conf;
                op_seen_q <= h_seen1;
                op_typ_q  <= iss_typ;
                op_vis_q  <= (q_asg & (~h_tent | h_conf)) | (iss_lift & ~l_tent) | (iss_new & cf1_q);
                op_etyp_q <= (q_asg & h_tent) ? T_NEW : iss_typ;
                op_s_q    <= iss_s;
                op_so_q   <= iss_so;
                if (q_asg | iss_new) op_t_q <= iss_t;
            end else if (op_go) begin
                op_v_q <= 1'b0;
            end

            // ---- E1: miss counter; event -----------------------------------------------
            for (s_i = 0; s_i < MT; s_i = s_i + 1)
                if (op_go && op_typ_q != T_LIFT && op_so_q[s_i])
                    miss_q[s_i*HOLD_W +: HOLD_W] <= (op_typ_q == T_UPD) ? e1_miss + 1'b1
                                                                          : {HOLD_W{1'b0}};
            // a tentative slot's move: seen + 1, confirmed (E1 and a new's issue never
            // name the same slot: a new takes a free slot, a move an active one; and a
            // slot's move is released before the slot can be matched again, next frame)
            for (s_i = 0; s_i < MT; s_i = s_i + 1)
                if (op_go && op_tnt_q && op_so_q[s_i]) begin
                    seen_q[s_i*3 +: 3] <= op_seen_q;
                    if (op_cnf_q) tent_q[s_i] <= 1'b0;
                end
            // the event hold: E1's event waits for the next one (then the held one goes
            // out) or for the cycle after the events end (then it goes out marked last)
            fl_q <= ev_done;
            if (e1_ev) begin
                hev_v_q   <= 1'b1;
                hev_id_q  <= {e1_gen, op_s};
                hev_typ_q <= op_etyp_q;
                hev_d_q   <= (op_typ_q == T_LIFT) ? {lrec, {(TD_W-32){1'b0}}} : trec;
            end else if (fl_q) begin
                hev_v_q   <= 1'b0;
            end
            ev_valid_o <= hev_v_q & (e1_ev | fl_q);
            if (hev_v_q & (e1_ev | fl_q)) begin
                ev_frame_o <= frame_q;
                ev_id_o    <= hev_id_q;
                ev_type_o  <= hev_typ_q;
                {ev_x_o, ev_y_o, ev_strength_o, ev_axis_major_o, ev_axis_minor_o,
                 ev_angle_o, ev_flags_o} <= hev_d_q;
                ev_last_o  <= fl_q;
            end

            // ---- E2..E5 ------------------------------------------------------------------
            e2_v_q   <= op_go;
            e2_typ_q <= op_typ_q;
            e2_s_q   <= op_s;
            e2_up_q  <= (op_typ_q == T_UPD);
            e2_g_q   <= (op_typ_q == T_UPD) ? e1_gate : max_jump_i;
            // E2: the operation's slot gets its new gate (not for a lift)
            for (s_i = 0; s_i < MT; s_i = s_i + 1)
                if (e2_v_q && e2_typ_q != T_LIFT && e2_s_q == s_i[SB-1:0])
                    gate_q[s_i*16 +: 16] <= e2_gn;
            e3_v_q   <= e2_v_q;
            e3_typ_q <= e2_typ_q;
            e3_s_q   <= e2_s_q;
            e4_v_q   <= e3_v_q;
            e4_typ_q <= e3_typ_q;
            e4_s_q   <= e3_s_q;
            pw_q     <= e4_v_q & (e4_typ_q != T_LIFT);
            pw_s_q   <= e4_s_q;
            pw_x_q   <= np_x;
            pw_y_q   <= np_y;
            for (s_i = 0; s_i < MT; s_i = s_i + 1)
                if (pw_q && pw_s_q == s_i[SB-1:0]) begin
                    prx_q[s_i*PR_W +: PR_W] <= w_prx;
                    pry_q[s_i*PR_W +: PR_W] <= w_pry;
                end
        end
    end

endmodule

`default_nettype wire
