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
// Pipeline: stage 0 (the event's cycle) measures the latency (now - stamp, or
// now - trigger time); stage 1 (+1 cycle) updates last/min/max/count and sat_o and reads
// the histogram bin; stage 2 (+2 cycles) writes bin + 1 back, forwarding the value of a
// write to the same bin in the previous cycle, so back-to-back updates of one bin are
// exact.  The statistics outputs thus show an event 1 cycle after it (sat_o 1 or 2
// cycles), the histograms 2 cycles after it.  clear_i also drops the events of its own
// cycle and of the cycle before (still in stages 0 and 1): the same counts as clearing
// after them.  One event per cycle at most, no stall: any frame rate is fine.
// Implementation: each histogram is a small distributed RAM (asynchronous read, one
// write port).  A per-bin "holds data" bit (BINS flip-flops, cleared by rst/clear_i in
// one cycle, set by the bin's first update) masks the RAM word to 0: after a clear every
// bin reads 0 at once, without a sweep and without a reset on the RAM (which would
// prevent the RAM inference).  The frame-end time-stamp table is a distributed RAM too,
// with a per-slot bit (cleared by rst only) that makes a slot's stamp read 0 until its
// first frame end.
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
    // stage 1: the measured event (from stage 0)
    reg                s1_first_q, s1_last_q, s1_trig_q;
    reg  [CNT_W-1:0]   s1_age_q, s1_tage_q;
    reg                s1_big_q, s1_tbig_q;
    reg                s1_over_q;            // age (below the saturation) beyond the top bin
    // stage 2: histogram write-back
    reg                s2_first_q, s2_last_q;
    reg  [HIST_BINS_W-1:0] s2_bin_q;
    reg  [NUM_W-1:0]   s2_hf_q, s2_hl_q;     // bin contents read in stage 1
    // forwarding: stage 2 takes the value written in the previous cycle when that write
    // was to its bin (the select is decided one cycle ahead)
    reg                fw_f_q, fw_l_q;
    reg  [NUM_W-1:0]   fw_f_val_q, fw_l_val_q;

    integer i;

    // ---- stage 0: the event of this cycle is measured
    wire [FRAME_SLOTS_W-1:0] ev_slot  = ev_slot_i;
    wire [TIME_W-1:0]        ev_stamp = stamp_ok_q[ev_slot] ? stamp_mem[ev_slot] : {TIME_W{1'b0}};
    wire [TIME_W-1:0]        ev_age   = now_q - ev_stamp;
    wire                     ev_big   = (ev_age > {{(TIME_W-CNT_W){1'b0}}, CNT_MAX});
    wire [CNT_W-1:0]         ev_sh    = ev_age[CNT_W-1:0] >> HIST_SHIFT;
    wire                     ev_over  = (ev_sh > BINS - 1);
    wire                     is_first = ev_fire_i && !seen_first_q[ev_slot];
    wire                     is_last  = ev_fire_i && ev_last_i;

    wire                     trig_rise = trig_sync_q[1] && !trig_sync_q[2];
    wire [TIME_W-1:0]        trig_age  = now_q - trig_start_q;
    wire                     trig_big  = (trig_age > {{(TIME_W-CNT_W){1'b0}}, CNT_MAX});
    wire                     trig_done = trig_armed_o && ev_fire_i && ev_new_i;

    // ---- stage 1: statistics, histogram bin and its read
    wire [CNT_W-1:0]         lat      = s1_big_q  ? CNT_MAX : s1_age_q;
    wire [CNT_W-1:0]         trig_lat = s1_tbig_q ? CNT_MAX : s1_tage_q;
    // bin: lat >> HIST_SHIFT, the top bin for everything above (saturated: CNT_MAX's bin)
    localparam [CNT_W-1:0]   MAX_SH  = CNT_MAX >> HIST_SHIFT;
    localparam [HIST_BINS_W-1:0] MAX_BIN = (MAX_SH > BINS - 1) ? BINS[HIST_BINS_W-1:0] - 1'b1
                                                               : MAX_SH[HIST_BINS_W-1:0];
    // only the low HIST_BINS_W bits of the shifted age are a bin (the rest is s1_over_q)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [CNT_W-1:0]         age_sh   = s1_age_q >> HIST_SHIFT;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [HIST_BINS_W-1:0]   hist_idx = s1_big_q  ? MAX_BIN :
                                        s1_over_q ? BINS[HIST_BINS_W-1:0] - 1'b1
                                                  : age_sh[HIST_BINS_W-1:0];
    wire [NUM_W-1:0]         hf_rd = hist_first_ok_q[hist_idx] ? hist_first_mem[hist_idx]
                                                                : {NUM_W{1'b0}};
    wire [NUM_W-1:0]         hl_rd = hist_last_ok_q[hist_idx] ? hist_last_mem[hist_idx]
                                                               : {NUM_W{1'b0}};
    wire [NUM_W:0]           first_cnt_inc = {1'b0, first_count_o} + 1'b1;  // carry = saturated
    wire [NUM_W:0]           last_cnt_inc  = {1'b0, last_count_o} + 1'b1;
    wire [NUM_W:0]           trig_cnt_inc  = {1'b0, trig_count_o} + 1'b1;

    // ---- stage 2: bin + 1, saturating (the carry out is the saturation), written back
    wire [NUM_W-1:0]         hf_cur = fw_f_q ? fw_f_val_q : s2_hf_q;
    wire [NUM_W-1:0]         hl_cur = fw_l_q ? fw_l_val_q : s2_hl_q;
    wire [NUM_W:0]           hf_inc = {1'b0, hf_cur} + 1'b1;
    wire [NUM_W:0]           hl_inc = {1'b0, hl_cur} + 1'b1;
    wire [NUM_W-1:0]         hf_new = hf_inc[NUM_W-1:0] | {NUM_W{hf_inc[NUM_W]}};
    wire [NUM_W-1:0]         hl_new = hl_inc[NUM_W-1:0] | {NUM_W{hl_inc[NUM_W]}};
    wire                     hf_we  = s2_first_q && !rst && !clear_i;
    wire                     hl_we  = s2_last_q  && !rst && !clear_i;

    always @(posedge clk) begin
        if (rst) begin
            now_q         <= {TIME_W{1'b0}};
            seen_first_q  <= {SLOTS{1'b1}};
            trig_sync_q   <= 3'b000;
            trig_start_q  <= {TIME_W{1'b0}};
            trig_armed_o  <= 1'b0;
            sat_o         <= 1'b0;
            stamp_ok_q    <= {SLOTS{1'b0}};
            s1_first_q    <= 1'b0;
            s1_last_q     <= 1'b0;
            s1_trig_q     <= 1'b0;
            s2_first_q    <= 1'b0;
            s2_last_q     <= 1'b0;
            fw_f_q        <= 1'b0;
            fw_l_q        <= 1'b0;
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
            // pipeline valid bits: a clear drops what it finds in stages 0 and 1
            s1_first_q <= is_first  && !clear_i;
            s1_last_q  <= is_last   && !clear_i;
            s1_trig_q  <= trig_done && !clear_i;
            s2_first_q <= s1_first_q && !clear_i;
            s2_last_q  <= s1_last_q  && !clear_i;
            fw_f_q     <= hf_we && (hist_idx == s2_bin_q);
            fw_l_q     <= hl_we && (hist_idx == s2_bin_q);
            // sticky saturation: stage 1 (values, counters), stage 2 (bins)
            if ((s1_first_q || s1_last_q) && s1_big_q) sat_o <= 1'b1;
            if (s1_trig_q && s1_tbig_q) sat_o <= 1'b1;
            if ((s1_first_q && first_cnt_inc[NUM_W]) || (s1_last_q && last_cnt_inc[NUM_W]) ||
                (s1_trig_q && trig_cnt_inc[NUM_W]))
                sat_o <= 1'b1;
            if ((s2_first_q && hf_inc[NUM_W]) || (s2_last_q && hl_inc[NUM_W]))
                sat_o <= 1'b1;
        end
    end

    // pipeline data (no reset needed: qualified by the valid bits)
    always @(posedge clk) begin
        s1_age_q   <= ev_age[CNT_W-1:0];
        s1_big_q   <= ev_big;
        s1_over_q  <= ev_over;
        s1_tage_q  <= trig_age[CNT_W-1:0];
        s1_tbig_q  <= trig_big;
        s2_bin_q   <= hist_idx;
        s2_hf_q    <= hf_rd;
        s2_hl_q    <= hl_rd;
        fw_f_val_q <= hf_new;
        fw_l_val_q <= hl_new;
    end

    // statistics (cleared by rst or clear_i), from stage 1
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
            if (s1_first_q) begin
                first_last_o <= lat;
                if (lat < first_min_o) first_min_o <= lat;
                if (lat > first_max_o) first_max_o <= lat;
                if (!first_cnt_inc[NUM_W]) first_count_o <= first_cnt_inc[NUM_W-1:0];
            end
            if (s1_last_q) begin
                last_last_o <= lat;
                if (lat < last_min_o) last_min_o <= lat;
                if (lat > last_max_o) last_max_o <= lat;
                if (!last_cnt_inc[NUM_W]) last_count_o <= last_cnt_inc[NUM_W-1:0];
            end
            if (s1_trig_q) begin
                trig_last_o <= trig_lat;
                if (trig_lat < trig_min_o) trig_min_o <= trig_lat;
                if (trig_lat > trig_max_o) trig_max_o <= trig_lat;
                if (!trig_cnt_inc[NUM_W]) trig_count_o <= trig_cnt_inc[NUM_W-1:0];
            end
            if (hf_we) hist_first_ok_q[s2_bin_q] <= 1'b1;
            if (hl_we) hist_last_ok_q[s2_bin_q]  <= 1'b1;
        end
    end

    // histogram RAMs: one write port (stage 2), the stage-1 read port and the readout
    // port; time-stamp RAM: written at frame ends, read at the event's slot
    always @(posedge clk) begin
        if (frame_end_i && !rst) stamp_mem[frame_end_slot_i] <= now_q;
        if (hf_we) hist_first_mem[s2_bin_q] <= hf_new;
        if (hl_we) hist_last_mem[s2_bin_q]  <= hl_new;
    end

    // reads 0 on the cycle after a reset (the valid bits were not cleared yet when it read)
    always @(posedge clk) begin
        if (rst)
            hist_data_o <= {NUM_W{1'b0}};
        else if (hist_sel_i)
            hist_data_o <= hist_last_ok_q[hist_addr_i] ? hist_last_mem[hist_addr_i] : {NUM_W{1'b0}};
        else
            hist_data_o <= hist_first_ok_q[hist_addr_i] ? hist_first_mem[hist_addr_i] : {NUM_W{1'b0}};
    end

`ifdef FORMAL
    // Formal properties (SymbiYosys, formal/fmt_latency.sby, at small widths; never seen
    // by synthesis): counters saturate instead of wrapping and say so, the histograms
    // count every measured event exactly once (bin forwarding included), reset and
    // clear give the documented state one cycle later.
    reg f_past_q = 1'b0;
    always @(posedge clk) f_past_q <= 1'b1;
    always @(*) if (!f_past_q) assume (rst);
    // shadow counts of the events through stage 1, one bit wider, stopping at 2^NUM_W
    localparam [NUM_W:0] F_TOP = {1'b1, {NUM_W{1'b0}}};
    localparam [NUM_W-1:0] F_MAX = {NUM_W{1'b1}};
    reg [NUM_W:0] f_nf_q, f_nl_q, f_nt_q;
    always @(posedge clk) begin
        if (rst || clear_i) begin
            f_nf_q <= {(NUM_W+1){1'b0}};
            f_nl_q <= {(NUM_W+1){1'b0}};
            f_nt_q <= {(NUM_W+1){1'b0}};
        end else begin
            if (s1_first_q && f_nf_q != F_TOP) f_nf_q <= f_nf_q + 1'b1;
            if (s1_last_q  && f_nl_q != F_TOP) f_nl_q <= f_nl_q + 1'b1;
            if (s1_trig_q  && f_nt_q != F_TOP) f_nt_q <= f_nt_q + 1'b1;
        end
    end
    // what a reader of the histograms sees, summed over the bins
    localparam SUM_W = NUM_W + HIST_BINS_W + 1;
    reg [SUM_W-1:0] f_hf_sum, f_hl_sum;
    integer fb;
    always @(*) begin
        f_hf_sum = {SUM_W{1'b0}};
        f_hl_sum = {SUM_W{1'b0}};
        for (fb = 0; fb < BINS; fb = fb + 1) begin
            if (hist_first_ok_q[fb]) f_hf_sum = f_hf_sum + hist_first_mem[fb];
            if (hist_last_ok_q[fb])  f_hl_sum = f_hl_sum + hist_last_mem[fb];
        end
    end
    wire [NUM_W-1:0] f_nf = f_nf_q[NUM_W] ? F_MAX : f_nf_q[NUM_W-1:0];
    wire [NUM_W-1:0] f_nl = f_nl_q[NUM_W] ? F_MAX : f_nl_q[NUM_W-1:0];
    wire [NUM_W-1:0] f_nt = f_nt_q[NUM_W] ? F_MAX : f_nt_q[NUM_W-1:0];
    always @(posedge clk) begin
        if (f_past_q && !$past(rst)) begin
            // counts: exact below the top, then stuck at all ones with sat_o set
            assert (first_count_o == f_nf && last_count_o == f_nl && trig_count_o == f_nt);
            assert (f_nf_q <= F_TOP && f_nl_q <= F_TOP && f_nt_q <= F_TOP);
            if (f_nf_q[NUM_W] || f_nl_q[NUM_W] || f_nt_q[NUM_W]) assert (sat_o);
            // sat_o is sticky
            assert (!$past(sat_o) || sat_o);
            // min / last / max are ordered once there is an event, untouched before
            if (first_count_o != 0) assert (first_min_o <= first_last_o && first_last_o <= first_max_o);
            else                    assert (first_min_o == CNT_MAX && first_max_o == 0);
            if (last_count_o != 0)  assert (last_min_o <= last_last_o && last_last_o <= last_max_o);
            else                    assert (last_min_o == CNT_MAX && last_max_o == 0);
            if (trig_count_o != 0)  assert (trig_min_o <= trig_last_o && trig_last_o <= trig_max_o);
            else                    assert (trig_min_o == CNT_MAX && trig_max_o == 0);
            // the histograms hold every counted event once: the bins plus the event in
            // stage 2 are the count (while nothing saturated)
            if (!sat_o) begin
                assert (f_hf_sum + s2_first_q == first_count_o);
                assert (f_hl_sum + s2_last_q  == last_count_o);
            end
            // the forwarded value is the bin's stored value (inductive helpers)
            if (fw_f_q) assert (hist_first_ok_q[s2_bin_q] && hist_first_mem[s2_bin_q] == fw_f_val_q);
            if (fw_l_q) assert (hist_last_ok_q[s2_bin_q]  && hist_last_mem[s2_bin_q]  == fw_l_val_q);
            if (s2_first_q && !fw_f_q) assert (s2_hf_q == (hist_first_ok_q[s2_bin_q] ? hist_first_mem[s2_bin_q] : {NUM_W{1'b0}}));
            if (s2_last_q  && !fw_l_q) assert (s2_hl_q == (hist_last_ok_q[s2_bin_q]  ? hist_last_mem[s2_bin_q]  : {NUM_W{1'b0}}));
            // a clear empties the statistics and the pipeline one cycle later
            if ($past(clear_i))
                assert (first_count_o == 0 && last_count_o == 0 && trig_count_o == 0 &&
                        hist_first_ok_q == 0 && hist_last_ok_q == 0 && !s2_first_q && !s2_last_q);
        end
        // one cycle after reset: the reset state
        if (f_past_q && $past(rst))
            assert (now_q == 0 && !sat_o && !trig_armed_o && stamp_ok_q == 0 &&
                    seen_first_q == {SLOTS{1'b1}} && trig_sync_q == 3'b000 &&
                    !s1_first_q && !s1_last_q && !s1_trig_q && !s2_first_q && !s2_last_q &&
                    !fw_f_q && !fw_l_q && first_count_o == 0 && last_count_o == 0 &&
                    trig_count_o == 0 && first_min_o == CNT_MAX && first_max_o == 0 &&
                    hist_first_ok_q == 0 && hist_last_ok_q == 0);
    end
`endif

endmodule

`default_nettype wire
