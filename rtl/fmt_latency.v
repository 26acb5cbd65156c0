// fmt_latency -- latency counters of the core.
//
// Two measurements, both in processing-clock cycles:
//  1. Frame latency: from the cycle the last ADC sample of frame f entered the
//     receiver (`frame_end_i` with the low bits of f on `frame_end_slot_i`) to the first and to the last
//     touch event of frame f leaving the event port (`ev_fire_i`, the valid & ready
//     handshake, with `ev_slot_i` and `ev_last_i`).  Frames overlap (the budget,
//     8 us, is longer than a window, 6.144 us), so the frame-end time stamps are kept
//     in a small table indexed by the low FRAME_SLOTS_W bits of the frame number.
//     For each of "first" and "last": last value, min, max, count, and a histogram of
//     HIST_BINS bins of 2^HIST_SHIFT cycles (the top bin collects everything above).
//  2. Touch-to-data latency (the paper's piezo tap sensor): a rising edge on the
//     asynchronous `trig_i` (synchronised here, 2 flip-flops; the synchroniser delay
//     is included in the count) starts a counter that stops at the next new-contact
//     event; last/min/max/count of that.  A second trigger while armed restarts it.
//
// `clear_i` resets min/max/count/histograms (not the time-stamp table).  All counters
// saturate at their maximum instead of wrapping; `sat_o` is sticky.
// The histogram is read through a window: `hist_sel_i` (0 = first-event, 1 = last-event)
// and `hist_addr_i` -> `hist_data_o` (registered, one cycle).
// Implementation: each histogram is a small distributed RAM (asynchronous read, one
// write port) with ONE read-modify-write incrementer at the event's bin, read in the
// same cycle, so back-to-back updates are exact.  A per-bin "holds data" bit (BINS
// flip-flops, cleared by rst/clear_i in one cycle, set by the bin's first update)
// masks the RAM word to 0: after a clear every bin reads 0 at once, without a sweep
// and without a reset on the RAM (which would prevent the RAM inference).  The
// frame-end time-stamp table is a distributed RAM too, with a per-slot bit (cleared
// by rst only) that makes a slot's stamp read 0 until its first frame end.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_latency #(
    parameter CNT_W         = 16,  // width of a latency value (cycles)
    parameter NUM_W         = 32,  // width of event/frame counters and histogram bins
    parameter FRAME_SLOTS_W = 2,   // frames in flight tracked: 2^FRAME_SLOTS_W
    parameter HIST_BINS_W   = 4,   // histogram has 2^HIST_BINS_W bins
    parameter HIST_SHIFT    = 5,   // bin width = 2^HIST_SHIFT cycles
    parameter TIME_W        = 32   // free-running time-stamp counter width
) (
    input  wire                   clk,
    input  wire                   rst,            // synchronous, active high
    input  wire                   clear_i,        // clear statistics
    input  wire                   frame_end_i,    // last ADC sample of a frame this cycle
    input  wire [FRAME_SLOTS_W-1:0] frame_end_slot_i, // its frame number, low FRAME_SLOTS_W bits
    input  wire                   ev_fire_i,      // an event leaves the port this cycle
    input  wire [FRAME_SLOTS_W-1:0] ev_slot_i,    // its frame number, low FRAME_SLOTS_W bits
    input  wire                   ev_last_i,      // it is the frame's last event
    input  wire                   ev_new_i,       // it is a new-contact event
    input  wire                   trig_i,         // external touch trigger (asynchronous)
    output reg  [CNT_W-1:0]       first_last_o,   // window end -> first event
    output reg  [CNT_W-1:0]       first_min_o,
    output reg  [CNT_W-1:0]       first_max_o,
    output reg  [NUM_W-1:0]       first_count_o,
    output reg  [CNT_W-1:0]       last_last_o,    // window end -> last event
    output reg  [CNT_W-1:0]       last_min_o,
    output reg  [CNT_W-1:0]       last_max_o,
    output reg  [NUM_W-1:0]       last_count_o,
    output reg  [CNT_W-1:0]       trig_last_o,    // trigger -> next new contact
    output reg  [CNT_W-1:0]       trig_min_o,
    output reg  [CNT_W-1:0]       trig_max_o,
    output reg  [NUM_W-1:0]       trig_count_o,
    output reg                    trig_armed_o,   // a trigger is waiting for its event
    input  wire                   hist_sel_i,     // 0 = first-event histogram, 1 = last-event
    input  wire [HIST_BINS_W-1:0] hist_addr_i,
    output reg  [NUM_W-1:0]       hist_data_o,
    output reg                    sat_o           // sticky: a value or counter saturated
);

    localparam SLOTS = 1 << FRAME_SLOTS_W;
    localparam BINS  = 1 << HIST_BINS_W;
    localparam [CNT_W-1:0] CNT_MAX = {CNT_W{1'b1}};
    localparam [NUM_W-1:0] NUM_MAX = {NUM_W{1'b1}};

    reg  [TIME_W-1:0]  now_q;
    reg  [TIME_W-1:0]  stamp_mem [0:SLOTS-1];  // frame-end time stamps, distributed RAM
    reg  [SLOTS-1:0]   stamp_ok_q;       // slot written since reset (else its stamp reads 0)
    reg  [SLOTS-1:0]   seen_first_q;     // slot's frame has had its first event
    reg  [NUM_W-1:0]   hist_first_mem [0:BINS-1];  // distributed RAM, no reset
    reg  [NUM_W-1:0]   hist_last_mem  [0:BINS-1];
    reg  [BINS-1:0]    hist_first_ok_q;  // bin written since the last clear (else reads 0)
    reg  [BINS-1:0]    hist_last_ok_q;
    reg  [2:0]         trig_sync_q;      // 2-FF synchroniser + edge detector
    reg  [TIME_W-1:0]  trig_start_q;

    integer i;

    // latency of the current event, saturated to CNT_W bits
    wire [FRAME_SLOTS_W-1:0] ev_slot  = ev_slot_i;
    wire [TIME_W-1:0]        ev_stamp = stamp_ok_q[ev_slot] ? stamp_mem[ev_slot] : {TIME_W{1'b0}};
    wire [TIME_W-1:0]        ev_age   = now_q - ev_stamp;
    wire                     ev_big   = (ev_age > {{(TIME_W-CNT_W){1'b0}}, CNT_MAX});
    wire [CNT_W-1:0]         ev_lat   = ev_big ? CNT_MAX : ev_age[CNT_W-1:0];
    wire                     is_first = ev_fire_i && !seen_first_q[ev_slot];
    wire                     is_last  = ev_fire_i && ev_last_i;
    wire [CNT_W-1:0]         hist_idx_full = ev_lat >> HIST_SHIFT;
    wire [HIST_BINS_W-1:0]   hist_idx = (hist_idx_full > BINS - 1) ? BINS[HIST_BINS_W-1:0] - 1'b1
                                                                  : hist_idx_full[HIST_BINS_W-1:0];

    // current contents of the event's bin (0 when not written since the clear)
    wire [NUM_W-1:0]         hf_cur = hist_first_ok_q[hist_idx] ? hist_first_mem[hist_idx]
                                                                 : {NUM_W{1'b0}};
    wire [NUM_W-1:0]         hl_cur = hist_last_ok_q[hist_idx] ? hist_last_mem[hist_idx]
                                                                : {NUM_W{1'b0}};
    wire                     hf_we  = is_first && hf_cur != NUM_MAX && !rst && !clear_i;
    wire                     hl_we  = is_last  && hl_cur != NUM_MAX && !rst && !clear_i;

    wire                     trig_rise = trig_sync_q[1] && !trig_sync_q[2];
    wire [TIME_W-1:0]        trig_age  = now_q - trig_start_q;
    wire                     trig_big  = (trig_age > {{(TIME_W-CNT_W){1'b0}}, CNT_MAX});
    wire [CNT_W-1:0]         trig_lat  = trig_big ? CNT_MAX : trig_age[CNT_W-1:0];
    wire                     trig_done = trig_armed_o && ev_fire_i && ev_new_i;

    always @(posedge clk) begin
        if (rst) begin
            now_q         <= {TIME_W{1'b0}};
            seen_first_q  <= {SLOTS{1'b1}};
            trig_sync_q   <= 3'b000;
            trig_start_q  <= {TIME_W{1'b0}};
            trig_armed_o  <= 1'b0;
            sat_o         <= 1'b0;
            stamp_ok_q    <= {SLOTS{1'b0}};
        end else begin
            now_q       <= now_q + 1'b1;
            trig_sync_q <= {trig_sync_q[1:0], trig_i};
            if (frame_end_i) stamp_ok_q[frame_end_slot_i] <= 1'b1;
            // a slot is re-armed by its frame end; the event bookkeeping of the same
            // cycle belongs to an older frame in another slot
            for (i = 0; i < SLOTS; i = i + 1) begin
                if (frame_end_i && frame_end_slot_i == i[FRAME_SLOTS_W-1:0])
                    seen_first_q[i] <= 1'b0;
                else if (is_first && ev_slot == i[FRAME_SLOTS_W-1:0])
                    seen_first_q[i] <= 1'b1;
            end
            if (trig_rise) begin
                trig_armed_o <= 1'b1;
                trig_start_q <= now_q - {{(TIME_W-2){1'b0}}, 2'd2};   // the edge entered the synchroniser 2 cycles ago
            end else if (trig_done) begin
                trig_armed_o <= 1'b0;
            end
            if ((is_first || is_last) && ev_big) sat_o <= 1'b1;
            if (trig_done && trig_big) sat_o <= 1'b1;
            if ((is_first && (first_count_o == NUM_MAX || hf_cur == NUM_MAX)) ||
                (is_last  && (last_count_o  == NUM_MAX || hl_cur == NUM_MAX)) ||
                (trig_done && trig_count_o == NUM_MAX))
                sat_o <= 1'b1;
        end
    end

    // statistics (cleared by rst or clear_i)
    always @(posedge clk) begin
        if (rst || clear_i) begin
            first_last_o  <= {CNT_W{1'b0}};
            first_min_o   <= CNT_MAX;
            first_max_o   <= {CNT_W{1'b0}};
            first_count_o <= {NUM_W{1'b0}};
            last_last_o   <= {CNT_W{1'b0}};
            last_min_o    <= CNT_MAX;
            last_max_o    <= {CNT_W{1'b0}};
            last_count_o  <= {NUM_W{1'b0}};
            trig_last_o   <= {CNT_W{1'b0}};
            trig_min_o    <= CNT_MAX;
            trig_max_o    <= {CNT_W{1'b0}};
            trig_count_o  <= {NUM_W{1'b0}};
            hist_first_ok_q <= {BINS{1'b0}};
            hist_last_ok_q  <= {BINS{1'b0}};
        end else begin
            if (is_first) begin
                first_last_o <= ev_lat;
                if (ev_lat < first_min_o) first_min_o <= ev_lat;
                if (ev_lat > first_max_o) first_max_o <= ev_lat;
                if (first_count_o != NUM_MAX) first_count_o <= first_count_o + 1'b1;
                hist_first_ok_q[hist_idx] <= 1'b1;
            end
            if (is_last) begin
                last_last_o <= ev_lat;
                if (ev_lat < last_min_o) last_min_o <= ev_lat;
                if (ev_lat > last_max_o) last_max_o <= ev_lat;
                if (last_count_o != NUM_MAX) last_count_o <= last_count_o + 1'b1;
                hist_last_ok_q[hist_idx] <= 1'b1;
            end
            if (trig_done) begin
                trig_last_o <= trig_lat;
                if (trig_lat < trig_min_o) trig_min_o <= trig_lat;
                if (trig_lat > trig_max_o) trig_max_o <= trig_lat;
                if (trig_count_o != NUM_MAX) trig_count_o <= trig_count_o + 1'b1;
            end
        end
    end

    // histogram RAMs: one read-modify-write port (the event's bin) + the readout port;
    // time-stamp RAM: written at frame ends, read at the event's slot
    always @(posedge clk) begin
        if (frame_end_i && !rst) stamp_mem[frame_end_slot_i] <= now_q;
        if (hf_we) hist_first_mem[hist_idx] <= hf_cur + 1'b1;
        if (hl_we) hist_last_mem[hist_idx]  <= hl_cur + 1'b1;
    end

    always @(posedge clk) begin
        if (hist_sel_i)
            hist_data_o <= hist_last_ok_q[hist_addr_i] ? hist_last_mem[hist_addr_i] : {NUM_W{1'b0}};
        else
            hist_data_o <= hist_first_ok_q[hist_addr_i] ? hist_first_mem[hist_addr_i] : {NUM_W{1'b0}};
    end

endmodule

`default_nettype wire
