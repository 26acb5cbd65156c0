// fmt_event_port -- the touch-event port: time stamps, dial-a-latency, report-rate
// decimation and whole-frame drops, in front of a valid/ready event stream.
//
// Twin: sim/fmt/event_port.py (EventPort.tick, cycle-exact).
//
// Input: the tracker's events (one per cycle at most, no back-pressure, in_last_i on a
// frame's last event).  Each event is stamped with the free-running cycle counter
// (ev_time = now in the cycle it arrives) and written into a FIFO of DEPTH entries
// (inferred block RAM, read-first).  Output: a registered valid/ready stream; the
// fields hold while ev_valid_o is high and ev_ready_i low.
//
// Timing: an event arriving in cycle c is on the output in cycle c + 5 + delay_i
// (RAM write, RAM read, head register, eligibility register, output register; the dial
// adds exactly delay_i cycles, 0 adds nothing) when the consumer is ready and nothing
// queues in front of it: the head event leaves only when now - ev_time >= delay + 4
// (mod 2^TIME_W).  Events keep their input spacing (one per cycle at most, any
// frame rate).  Largest loss-free delay: the FIFO must hold every
// event younger than the delay, (DEPTH / MAX_EV - 1) admitted frames: at every frame
// (162.76 kHz, DEPTH 2048, MAX_EV 32) 63 frames = 387 us; at a 250 Hz report rate
// 63 x 4 ms = 252 ms (the paper's 150 ms Pong delay fits).
//
// Structure: the RAM is read ahead (read enable, address = read pointer) through a
// chain: its read register q_q, then flip-flops next_q (the read data goes straight into
// them) and head_q; each moves when the one after it is free, so the port still takes
// and gives one event per cycle.  The pop decision is the register elig_q, computed one
// cycle ahead from the head's and the next entry's time stamps against now + 1, so
// nothing decided in a cycle depends on the RAM's output of that cycle.  The admission conditions (room,
// report period) are registers computed one cycle ahead too; delay_i and
// report_period_i act one cycle after they change.
//
// Admission, decided at a frame's first event for the whole frame:
//   report_period_i > 0 and fewer than report_period_i cycles since the last admitted
//     frame's first event -> skipped (skip_count_o);
//   else DEPTH - count < MAX_EV (no room for the largest possible frame) -> dropped
//     (drop_count_o, sticky overflow_o);
//   else admitted: all its events are written (room is reserved), so a frame is never
//   split and an event never corrupted however long ev_ready_i stays low.
// Counters saturate at all ones.  Share rst with the tracker (a port-only reset in
// the middle of a frame would take the rest of that frame for a new frame).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_event_port #(
    parameter HM_W     = `FMT_HM_W,               // strength width
    parameter FRAME_W  = 16,                      // frame number width
    parameter ID_W     = 8,                       // contact ID width
    parameter TIME_W   = 32,                      // time stamp, delay and period width
    parameter DEPTH    = 2048,                    // FIFO entries (power of two)
    parameter MAX_EV   = 2 * `FMT_MAX_TOUCHES,    // room reserved per frame (events)
    parameter CNT_W    = 16,                      // drop / skip counter width
    parameter AW       = $clog2(DEPTH)            // FIFO address width
) (
    input  wire                 clk,
    input  wire                 rst,               // synchronous, active high
    // settings
    input  wire [TIME_W-1:0]    delay_i,           // extra latency in cycles (dial)
    input  wire [TIME_W-1:0]    report_period_i,   // min cycles between admitted frames (0 = all)
    // events in (fmt_tracker)
    input  wire                 in_valid_i,        // one event this cycle
    input  wire [FRAME_W-1:0]   in_frame_i,        // frame number
    input  wire [ID_W-1:0]      in_id_i,           // contact ID
    input  wire [1:0]           in_type_i,         // 0 new, 1 move, 2 lift, 3 blob
    input  wire [15:0]          in_x_i,            // Q8.8
    input  wire [15:0]          in_y_i,            // Q8.8
    input  wire [HM_W-1:0]      in_strength_i,     // peak cell value
    input  wire [15:0]          in_axis_major_i,   // Q8.8
    input  wire [15:0]          in_axis_minor_i,   // Q8.8
    input  wire [7:0]           in_angle_i,        // pi/256
    input  wire [7:0]           in_flags_i,        // flags
    input  wire                 in_last_i,         // last event of the frame
    // events out (valid / ready)
    output reg                  ev_valid_o,        // an event is offered
    input  wire                 ev_ready_i,        // the consumer takes it
    output reg  [FRAME_W-1:0]   ev_frame_o,        // frame number
    output reg  [TIME_W-1:0]    ev_time_o,         // arrival time stamp (cycles since reset)
    output reg  [ID_W-1:0]      ev_id_o,           // contact ID
    output reg  [1:0]           ev_type_o,         // event type
    output reg  [15:0]          ev_x_o,            // Q8.8
    output reg  [15:0]          ev_y_o,            // Q8.8
    output reg  [HM_W-1:0]      ev_strength_o,     // peak cell value
    output reg  [15:0]          ev_axis_major_o,   // Q8.8
    output reg  [15:0]          ev_axis_minor_o,   // Q8.8
    output reg  [7:0]           ev_angle_o,        // pi/256
    output reg  [7:0]           ev_flags_o,        // flags
    output reg                  ev_last_o,         // last event of the frame
    // monitor
    output wire [TIME_W-1:0]    now_o,             // the time-stamp counter
    output reg  [CNT_W-1:0]     drop_count_o,      // frames dropped for lack of room
    output reg  [CNT_W-1:0]     skip_count_o,      // frames skipped by the report rate
    output reg                  overflow_o         // sticky: a frame was dropped
);

    localparam integer ROOM_I  = DEPTH - MAX_EV;
    localparam integer DEPTH_I = DEPTH;
    localparam [AW:0]  ROOM    = ROOM_I[AW:0];      // count <= ROOM: a whole frame fits
    localparam [AW:0]  FULL    = DEPTH_I[AW:0];
    localparam integer FULL_M1_I = DEPTH_I - 1;
    localparam [AW:0]  FULL_M1 = FULL_M1_I[AW:0];
    localparam [TIME_W:0] NEED_EXTRA = 4;           // fixed latency 5 = NEED_EXTRA + 1
    localparam RW = FRAME_W + TIME_W + ID_W + 2 + 16 + 16 + HM_W + 16 + 16 + 8 + 8 + 1;
    localparam TLSB = RW - FRAME_W - TIME_W;        // time stamp field: [TLSB +: TIME_W]

    // read data on a read/write collision is never used (a read is issued only for an
    // address written in an earlier cycle): no collision circuit around the block RAM
    (* no_rw_check *)
    reg [RW-1:0]     mem [0:DEPTH-1];
    reg [TIME_W-1:0] now_q, nxt_q;                  // nxt_q = now_q + 1
    reg [TIME_W:0]   need_q;                        // delay_i + 4 of the previous cycle
    reg [AW-1:0]     wr_ptr_q, rd_ptr_q;
    reg [AW:0]       count_q;                       // events held (RAM, read register, window)
    reg              room_q, not_full_q;
    reg [RW-1:0]     q_q;                           // RAM read register (in the block RAM)
    reg [RW-1:0]     next_q, head_q;                // flip-flops after the RAM: next, head
    reg              q_v_q, next_v_q, head_v_q;
    reg              elig_q;                        // the head leaves this cycle if the output is free
    reg              in_frame_q, admit_q, have_admit_q, dok_q;
    reg [TIME_W-1:0] last_admit_m1_q;               // time of the last admitted frame - 1

    assign now_o = now_q;

    wire              pop      = elig_q && (!ev_valid_o || ev_ready_i);
    // read pipeline RAM -> q_q -> next_q -> head_q: each moves when the one after it is free
    wire              keep_h   = head_v_q && !pop;
    wire              n_hold   = keep_h && next_v_q;      // next cannot move into head
    wire              q_hold   = n_hold && q_v_q;         // q cannot move into next
    wire              issue    = (wr_ptr_q != rd_ptr_q) && !q_hold;
    wire [TIME_W-1:0] head_age = nxt_q - head_q[TLSB +: TIME_W];   // age in the next cycle
    wire [TIME_W-1:0] next_age = nxt_q - next_q[TLSB +: TIME_W];
    wire              r_head   = head_v_q && ({1'b0, head_age} >= need_q);
    wire              r_next   = next_v_q && ({1'b0, next_age} >= need_q);
    wire              elig_d   = keep_h ? r_head : r_next;

    wire              first     = in_valid_i && !in_frame_q;
    wire              decide    = room_q && dok_q;
    wire              admit_cur = first ? decide : admit_q;
    wire              wr        = in_valid_i && admit_cur && not_full_q;
    wire              admit_now = first && decide;
    wire [TIME_W-1:0] since_p1  = now_q - last_admit_m1_q;         // cycles since, next cycle
    wire              p_zero    = (report_period_i == {TIME_W{1'b0}});
    wire              p_le1     = (report_period_i <= {{(TIME_W-1){1'b0}}, 1'b1});
    wire              dok_d     = admit_now ? p_le1
                                            : (p_zero || !have_admit_q || (since_p1 >= report_period_i));
    // the count after this cycle's pop, then + wr; the room and not-full flags are decided
    // for both values of wr and picked by it (wr comes last: in fmt_touch it is the end
    // of the emission mux, and a compare after the add made 9 xc5v levels there)
    wire [AW:0]       count_p   = count_q - {{AW{1'b0}}, pop};
    wire [AW:0]       count_d   = count_p + {{AW{1'b0}}, wr};
    wire              room_w    = (count_p <  ROOM);        // count_p + 1 <= ROOM
    wire              room_nw   = (count_p <= ROOM);
    wire              nfull_w   = (count_p <  FULL_M1);     // count_p + 1 < FULL
    wire              nfull_nw  = (count_p <  FULL);
    wire [RW-1:0]     din       = {in_frame_i, now_q, in_id_i, in_type_i, in_x_i, in_y_i,
                                   in_strength_i, in_axis_major_i, in_axis_minor_i,
                                   in_angle_i, in_flags_i, in_last_i};

    // block RAM: write port and registered read port with enable, no reset
    always @(posedge clk) begin
        if (wr)
            mem[wr_ptr_q] <= din;
        if (issue)
            q_q <= mem[rd_ptr_q];
    end

    // the read data goes straight into flip-flops (next_q), then head_q; no reset
    always @(posedge clk) begin
        if (!keep_h)
            head_q <= next_q;
        if (!n_hold)
            next_q <= q_q;
    end

    always @(posedge clk) begin
        if (rst) begin
            now_q        <= {TIME_W{1'b0}};
            nxt_q        <= {{(TIME_W-1){1'b0}}, 1'b1};
            need_q       <= NEED_EXTRA;
            wr_ptr_q     <= {AW{1'b0}};
            rd_ptr_q     <= {AW{1'b0}};
            count_q      <= {(AW+1){1'b0}};
            room_q       <= 1'b1;
            not_full_q   <= 1'b1;
            q_v_q        <= 1'b0;
            head_v_q     <= 1'b0;
            next_v_q     <= 1'b0;
            elig_q       <= 1'b0;
            in_frame_q   <= 1'b0;
            admit_q      <= 1'b0;
            have_admit_q <= 1'b0;
            dok_q        <= 1'b1;
            last_admit_m1_q <= {TIME_W{1'b1}};
            drop_count_o <= {CNT_W{1'b0}};
            skip_count_o <= {CNT_W{1'b0}};
            overflow_o   <= 1'b0;
            ev_valid_o   <= 1'b0;
            {ev_frame_o, ev_time_o, ev_id_o, ev_type_o, ev_x_o, ev_y_o, ev_strength_o,
             ev_axis_major_o, ev_axis_minor_o, ev_angle_o, ev_flags_o, ev_last_o} <= {RW{1'b0}};
        end else begin
            now_q  <= nxt_q;
            nxt_q  <= nxt_q + 1'b1;
            need_q <= {1'b0, delay_i} + NEED_EXTRA;
            // admission
            if (first) begin
                admit_q <= decide;
                if (decide) begin
                    last_admit_m1_q <= now_q - 1'b1;
                    have_admit_q    <= 1'b1;
                end else if (dok_q) begin
                    overflow_o <= 1'b1;
                    if (drop_count_o != {CNT_W{1'b1}}) drop_count_o <= drop_count_o + 1'b1;
                end else begin
                    if (skip_count_o != {CNT_W{1'b1}}) skip_count_o <= skip_count_o + 1'b1;
                end
            end
            dok_q <= dok_d;
            if (in_valid_i)
                in_frame_q <= !in_last_i;
            // FIFO
            if (wr)
                wr_ptr_q <= wr_ptr_q + 1'b1;
            if (issue)
                rd_ptr_q <= rd_ptr_q + 1'b1;
            count_q    <= count_d;
            room_q     <= wr ? room_w : room_nw;            // = (count_d <= ROOM)
            not_full_q <= wr ? nfull_w : nfull_nw;          // = (count_d < FULL)
            q_v_q      <= issue || q_hold;
            head_v_q   <= keep_h || next_v_q;
            next_v_q   <= n_hold || q_v_q;
            elig_q     <= elig_d;
            // output register
            if (pop) begin
                ev_valid_o <= 1'b1;
                {ev_frame_o, ev_time_o, ev_id_o, ev_type_o, ev_x_o, ev_y_o, ev_strength_o,
                 ev_axis_major_o, ev_axis_minor_o, ev_angle_o, ev_flags_o, ev_last_o} <= head_q;
            end else if (ev_ready_i) begin
                ev_valid_o <= 1'b0;
            end
        end
    end

`ifdef FORMAL
    // Formal properties (SymbiYosys, formal/fmt_event_port.sby; never seen by synthesis).
    // No loss, no duplication, in order: one event chosen by the solver (the f_k-th
    // written, any k) is followed through the RAM, the read register, next, head and
    // the output register, and leaves exactly as it was written, as the f_k-th event
    // the consumer takes.  Whole frames: with at most MAX_EV events per frame (an
    // assumption on the input, the tracker's bound), every event of an admitted frame is
    // written (never split) and none of a refused one.  Counters saturate.
    localparam F_CW = AW + 3;                        // event counters (they wrap)
    reg               f_rstd_q = 1'b0;
    reg  [F_CW-1:0]   f_w_q, f_i_q, f_p_q, f_c_q;    // written, read issued, popped, consumed
    (* anyconst *) reg [F_CW-1:0] f_k;               // the tracked event (f_k-th written)
    reg  [RW-1:0]     f_data_q;                      // its contents
    reg  [7:0]        f_nev_q;                       // events of the current frame so far
    reg               f_adm_q;                       // the current frame was admitted
    wire [RW-1:0]     f_out = {ev_frame_o, ev_time_o, ev_id_o, ev_type_o, ev_x_o, ev_y_o,
                               ev_strength_o, ev_axis_major_o, ev_axis_minor_o, ev_angle_o,
                               ev_flags_o, ev_last_o};
    wire              f_take = ev_valid_o && ev_ready_i;
    always @(posedge clk) begin
        f_rstd_q <= f_rstd_q | rst;
        if (rst) begin
            f_w_q <= 0; f_i_q <= 0; f_p_q <= 0; f_c_q <= 0; f_nev_q <= 8'd0; f_adm_q <= 1'b0;
        end else begin
            if (wr) f_w_q <= f_w_q + 1'b1;
            if (wr && f_w_q == f_k) f_data_q <= din;
            if (issue) f_i_q <= f_i_q + 1'b1;
            if (pop) f_p_q <= f_p_q + 1'b1;
            if (f_take) f_c_q <= f_c_q + 1'b1;
            if (in_valid_i) f_nev_q <= in_last_i ? 8'd0 : f_nev_q + 1'b1;
            if (first) f_adm_q <= decide;
        end
    end
    // the input: at most MAX_EV events per frame (the last one carries in_last_i)
    always @(*) if (f_rstd_q && !rst && in_valid_i && f_nev_q == MAX_EV - 1) assume (in_last_i);
    // the tracked event's place (counters wrap: only differences are compared)
    wire [F_CW-1:0] f_held = f_w_q - f_c_q;          // written, not yet taken
    wire [F_CW-1:0] f_ram  = f_w_q - f_i_q;          // in the RAM, not yet read
    wire [F_CW-1:0] f_pipe = f_i_q - f_c_q;          // read register .. output register
    wire [F_CW-1:0] f_kk   = f_k - f_c_q;            // the tracked event's place in line
    wire [F_CW-1:0] f_h    = {{(F_CW-1){1'b0}}, ev_valid_o};  // its place when in head
    wire [F_CW-1:0] f_n    = f_h + head_v_q;         // in next
    wire [F_CW-1:0] f_q    = f_n + next_v_q;         // in the read register
    wire [F_CW-1:0] f_kr   = f_kk - f_pipe;          // its offset in the RAM
    wire [AW-1:0]   f_ka   = rd_ptr_q + f_kr[AW-1:0];
    always @(*) begin
        if (f_rstd_q && !rst) begin
            assert (f_p_q - f_c_q == {{(F_CW-1){1'b0}}, ev_valid_o});
            assert (f_i_q - f_p_q == {{(F_CW-1){1'b0}}, q_v_q} + next_v_q + head_v_q);
            assert (f_ram <= DEPTH && wr_ptr_q == rd_ptr_q + f_ram[AW-1:0]);
            assert ({{(F_CW-AW-1){1'b0}}, count_q} == f_w_q - f_p_q && count_q <= DEPTH);
            assert (room_q == (count_q <= ROOM) && not_full_q == (count_q < FULL));
            if (elig_q) assert (head_v_q || next_v_q);
            // the tracked event, wherever it is, is unchanged
            if (f_kk < f_held) begin
                if (ev_valid_o && f_kk == 0)      assert (f_out == f_data_q);
                if (head_v_q && f_kk == f_h)      assert (head_q == f_data_q);
                if (next_v_q && f_kk == f_n)      assert (next_q == f_data_q);
                if (q_v_q && f_kk == f_q)         assert (q_q == f_data_q);
                if (f_kk >= f_pipe)               assert (mem[f_ka] == f_data_q);
            end
            // whole frames: an admitted frame is never split, a refused one never written
            if (in_valid_i && admit_cur) assert (wr);
            if (in_valid_i && !admit_cur) assert (!wr);
            if (in_frame_q) assert (admit_q == f_adm_q);
            if (in_frame_q && admit_q) assert (count_q + (MAX_EV - f_nev_q) <= DEPTH);  // room kept for the rest
            if (!in_frame_q) assert (f_nev_q == 8'd0);
            assert (f_nev_q < MAX_EV);
        end
    end
    // the consumer takes the tracked event as the f_k-th: no loss, no duplicate, in order
    always @(posedge clk)
        if (f_rstd_q && !rst && f_take && f_c_q == f_k) assert (f_held != 0 && f_out == f_data_q);
    // drop and skip counts: +1 per refused frame, saturating
    reg [CNT_W-1:0] f_dc_q, f_sc_q;
    reg             f_drop_q, f_skip_q;
    always @(posedge clk) begin
        f_dc_q <= drop_count_o; f_sc_q <= skip_count_o;
        f_drop_q <= !rst && first && !decide && dok_q;
        f_skip_q <= !rst && first && !decide && !dok_q;
        if (f_rstd_q && !rst && !$past(rst)) begin
            if (f_drop_q && f_dc_q != {CNT_W{1'b1}}) assert (drop_count_o == f_dc_q + 1'b1);
            else                                      assert (drop_count_o == f_dc_q);
            if (f_skip_q && f_sc_q != {CNT_W{1'b1}}) assert (skip_count_o == f_sc_q + 1'b1);
            else                                      assert (skip_count_o == f_sc_q);
            if (f_drop_q) assert (overflow_o);
        end
    end
`endif

endmodule

`default_nettype wire
