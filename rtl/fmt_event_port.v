// fmt_event_port -- the touch-event port: time stamps, dial-a-latency, report-rate
// decimation and whole-frame drops, in front of a valid/ready event stream.
//
// Twin: sim/fmt/events.py (EventPort.tick, cycle-exact).
//
// Input: the tracker's events (one per cycle at most, no back-pressure, in_last_i on a
// frame's last event).  Each event is stamped with the free-running cycle counter
// (ev_time = now in the cycle it arrives) and written into a FIFO of DEPTH entries
// (inferred block RAM, read-first).  Output: a registered valid/ready stream; the
// fields hold while ev_valid_o is high and ev_ready_i low.
//
// Timing: an event arriving in cycle c is on the output in cycle c + 3 + delay_i
// (RAM write, RAM read, output register; the dial adds exactly delay_i cycles, 0 adds
// nothing) when the consumer is ready and nothing queues in front of it: the head
// event leaves the RAM only when now - ev_time >= delay_i + 2 (mod 2^TIME_W).
// Events keep their input spacing.  Largest loss-free delay: the FIFO must hold every
// event younger than the delay, (DEPTH / MAX_EV - 1) admitted frames: at every frame
// (162.76 kHz, DEPTH 2048, MAX_EV 32) 63 frames = 387 us; at a 250 Hz report rate
// 63 x 4 ms = 252 ms (the paper's 150 ms Pong delay fits).
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
    localparam RW = FRAME_W + TIME_W + ID_W + 2 + 16 + 16 + HM_W + 16 + 16 + 8 + 8 + 1;

    reg [RW-1:0]     mem [0:DEPTH-1];
    reg [TIME_W-1:0] now_q;
    reg [AW-1:0]     wr_ptr_q, rd_ptr_q;
    reg [AW:0]       count_q;
    reg              head_ok_q;
    reg [RW-1:0]     head_q;
    reg              in_frame_q, admit_q, have_admit_q;
    reg [TIME_W-1:0] last_admit_q;

    assign now_o = now_q;

    wire [TIME_W-1:0] head_time = head_q[RW-FRAME_W-1 -: TIME_W];
    wire [TIME_W-1:0] age       = now_q - head_time;
    wire [TIME_W:0]   need      = {1'b0, delay_i} + {{(TIME_W-1){1'b0}}, 2'd2};  // delay + 2
    wire              eligible  = head_ok_q && ({1'b0, age} >= need);
    wire              pop       = eligible && (!ev_valid_o || ev_ready_i);

    wire              first     = in_valid_i && !in_frame_q;
    wire              room      = (count_q <= ROOM);
    wire [TIME_W-1:0] since     = now_q - last_admit_q;
    wire              decim_ok  = (report_period_i == {TIME_W{1'b0}}) || !have_admit_q ||
                                  (since >= report_period_i);
    wire              decide    = room && decim_ok;
    wire              admit_cur = first ? decide : admit_q;
    wire              wr        = in_valid_i && admit_cur && (count_q < FULL);
    wire [AW-1:0]     rd_addr   = rd_ptr_q + {{(AW-1){1'b0}}, pop};
    wire [RW-1:0]     din       = {in_frame_i, now_q, in_id_i, in_type_i, in_x_i, in_y_i,
                                   in_strength_i, in_axis_major_i, in_axis_minor_i,
                                   in_angle_i, in_flags_i, in_last_i};

    // block RAM: write port and registered (read-first) read port, no reset
    always @(posedge clk) begin
        if (wr)
            mem[wr_ptr_q] <= din;
        head_q <= mem[rd_addr];
    end

    always @(posedge clk) begin
        if (rst) begin
            now_q        <= {TIME_W{1'b0}};
            wr_ptr_q     <= {AW{1'b0}};
            rd_ptr_q     <= {AW{1'b0}};
            count_q      <= {(AW+1){1'b0}};
            head_ok_q    <= 1'b0;
            in_frame_q   <= 1'b0;
            admit_q      <= 1'b0;
            have_admit_q <= 1'b0;
            last_admit_q <= {TIME_W{1'b0}};
            drop_count_o <= {CNT_W{1'b0}};
            skip_count_o <= {CNT_W{1'b0}};
            overflow_o   <= 1'b0;
            ev_valid_o   <= 1'b0;
            {ev_frame_o, ev_time_o, ev_id_o, ev_type_o, ev_x_o, ev_y_o, ev_strength_o,
             ev_axis_major_o, ev_axis_minor_o, ev_angle_o, ev_flags_o, ev_last_o} <= {RW{1'b0}};
        end else begin
            now_q <= now_q + 1'b1;
            // admission
            if (first) begin
                admit_q <= decide;
                if (decide) begin
                    last_admit_q <= now_q;
                    have_admit_q <= 1'b1;
                end else if (decim_ok) begin
                    overflow_o <= 1'b1;
                    if (drop_count_o != {CNT_W{1'b1}}) drop_count_o <= drop_count_o + 1'b1;
                end else begin
                    if (skip_count_o != {CNT_W{1'b1}}) skip_count_o <= skip_count_o + 1'b1;
                end
            end
            if (in_valid_i)
                in_frame_q <= !in_last_i;
            // FIFO
            if (wr)
                wr_ptr_q <= wr_ptr_q + 1'b1;
            if (pop)
                rd_ptr_q <= rd_ptr_q + 1'b1;
            head_ok_q <= (count_q - {{AW{1'b0}}, pop}) != {(AW+1){1'b0}};
            count_q   <= count_q + {{AW{1'b0}}, wr} - {{AW{1'b0}}, pop};
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

endmodule

`default_nettype wire
