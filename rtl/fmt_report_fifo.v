// fmt_report_fifo -- whole, fresh reports for the UART event stream: a FIFO of events that
// admits a frame's events all together or not at all.
//
// Rule: events (in_valid_i, one per cycle at most, never back-pressured: this is a tap of
// the event port's handshake) are written as they come; the read side sees them only
// once the frame's last event (in_last_i) has been written.  A frame is admitted only if
// the FIFO is empty when its first event arrives (the previous report has been handed to
// the consumer, all but the event it is sending): the host gets the newest whole report,
// never one that waited behind others (at most one report plus the event in flight of
// lag).  A frame that arrives while a report is still waiting, or whose events do not
// all fit (the FIFO is full when one arrives: it is taken back out, the write pointer
// returns to the frame's start), is dropped whole: drop_o pulses and drop_count_o counts
// it (saturating).  So the host gets each report complete, with the 'last' flag that ends
// it, or not at all (frame numbers show the gap).  While en_i is low (STREAM off) the
// FIFO is empty and takes nothing; after it rises the first frame admitted is the first
// one that starts afterwards (a frame in progress is skipped, not counted as a drop).
// A frame of more than 2^AW events can never be admitted.
//
// Storage: 2^AW words of W bits, written synchronously and read asynchronously
// (distributed RAM; 192 x 32 = 128 LUT6 as RAM32M on Virtex-5).  Pointers are AW+1 bits.
// Latency: an event is readable the cycle after its frame's last event was written
// (out_valid_o from registered pointers; out_data_o is the RAM's asynchronous read of
// the read pointer, for a consumer that registers it when it takes it).
// Model twin: sim/fmt/report_fifo.py (ReportFifo, cycle by cycle).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_report_fifo #(
    parameter W  = 192,             // event payload width, bits
    parameter AW = 5                // log2 of the depth in events (2^AW events; >= 1)
) (
    input  wire         clk,
    input  wire         rst,           // synchronous, active high
    input  wire         en_i,          // stream on; low: empty the FIFO and take nothing
    input  wire         in_valid_i,    // an event of the stream (a tap: never held back)
    input  wire [W-1:0] in_data_i,     // its payload
    input  wire         in_last_i,     // last event of its frame
    output wire         out_valid_o,   // a committed event is waiting
    output wire [W-1:0] out_data_o,    // the oldest committed event
    input  wire         out_ready_i,   // the consumer takes it
    output reg          drop_o,        // one cycle: a frame was dropped (did not fit)
    output reg  [15:0]  drop_count_o   // frames dropped, saturating
);

    generate
        if (AW < 1) begin : g_bad_aw
            initial $error("fmt_report_fifo: AW = %0d, must be >= 1", AW);
        end
    endgenerate

    localparam PW = AW + 1;

    reg [W-1:0]  mem [0:(1 << AW) - 1];
    reg [PW-1:0] wp_q;              // next write (tentative: the frame being written)
    reg [PW-1:0] cp_q;              // end of the last complete frame
    reg [PW-1:0] rp_q;              // next read
    reg          skip_q;            // ignore events until the current frame's last one
    reg          mid_q;             // a frame of the stream is in progress (seen, en_i or not)

    wire full = (wp_q[AW] != rp_q[AW]) && (wp_q[AW-1:0] == rp_q[AW-1:0]);
    wire pop  = out_valid_o && out_ready_i;
    wire busy = !mid_q && (wp_q != rp_q);  // a frame starts while a report still waits
    wire ovf  = in_valid_i && en_i && !skip_q && (full || busy);
    wire wr   = in_valid_i && en_i && !skip_q && !ovf;

    assign out_valid_o = (rp_q != cp_q);
    assign out_data_o  = mem[rp_q[AW-1:0]];

    always @(posedge clk) begin
        if (wr) mem[wp_q[AW-1:0]] <= in_data_i;
    end

    always @(posedge clk) begin
        if (rst)             mid_q <= 1'b0;
        else if (in_valid_i) mid_q <= !in_last_i;
    end

    always @(posedge clk) begin
        if (rst || !en_i) begin
            wp_q   <= {PW{1'b0}};
            cp_q   <= {PW{1'b0}};
            rp_q   <= {PW{1'b0}};
            skip_q <= rst ? 1'b0 : (in_valid_i ? !in_last_i : mid_q);
        end else begin
            if (pop) rp_q <= rp_q + 1'b1;
            if (in_valid_i && skip_q) begin
                skip_q <= !in_last_i;
            end else if (ovf) begin
                wp_q   <= cp_q;
                skip_q <= !in_last_i;
            end else if (wr) begin
                wp_q <= wp_q + 1'b1;
                if (in_last_i) cp_q <= wp_q + 1'b1;
            end
        end
    end

    always @(posedge clk) begin
        if (rst) begin
            drop_o       <= 1'b0;
            drop_count_o <= 16'd0;
        end else begin
            drop_o <= ovf;
            if (ovf && (drop_count_o != 16'hFFFF)) drop_count_o <= drop_count_o + 1'b1;
        end
    end

`ifdef FORMAL
    // Formal properties (SymbiYosys, formal/fmt_report_fifo.sby at W = 4, AW = 2; never
    // seen by synthesis).  The promise: a consumer that has taken the first event of a
    // frame finds the rest of it waiting, cycle after cycle, until its last one (unless
    // the stream is switched off); the read side never sees a frame being written; a
    // frame is written only while nothing committed waits.
    localparam D = 1 << AW;
    reg f_rstd_q = 1'b0;                       // a reset has been applied
    always @(posedge clk) f_rstd_q <= f_rstd_q | rst;
    reg [D-1:0] f_last_q;                      // in_last_i of each written entry
    always @(posedge clk) if (wr) f_last_q[wp_q[AW-1:0]] <= in_last_i;
    reg f_mid_q;                               // the consumer is inside a frame
    always @(posedge clk) begin
        if (rst || !en_i) f_mid_q <= 1'b0;
        else if (pop)     f_mid_q <= !f_last_q[rp_q[AW-1:0]];
    end
    wire [PW-1:0] f_used = wp_q - rp_q;        // entries written (committed + tentative)
    wire [PW-1:0] f_comm = cp_q - rp_q;        // entries committed
    wire [PW-1:0] f_tent = wp_q - cp_q;        // entries of the frame being written
    wire [PW-1:0] f_cm1  = cp_q - 1'b1;
    reg  [PW-1:0] f_k;
    integer fi;
    always @(*) begin
        if (f_rstd_q && !rst) begin
            assert (f_comm <= f_used && f_used <= D);
            assert (out_valid_o == (f_comm != 0));
            // the committed entries end with a frame's last event ...
            if (f_comm != 0) assert (f_last_q[f_cm1[AW-1:0]]);
            // ... and the tentative ones hold none
            for (fi = 0; fi < D; fi = fi + 1) begin
                f_k = cp_q + fi;
                if (fi < f_tent) assert (!f_last_q[f_k[AW-1:0]]);
            end
            if (skip_q) assert (f_tent == 0);
            // fresh reports: a frame is written only into an empty FIFO
            if (f_tent != 0) assert (f_comm == 0 && mid_q);
            if (mid_q && !skip_q) assert (f_tent != 0);
            // whole frames: inside a frame, its next event is committed and waiting
            if (f_mid_q) assert (out_valid_o);
        end
    end
    // the drop counter counts every overflow, saturates, never wraps
    reg f_ovf_q = 1'b0;
    reg [15:0] f_cnt_q = 16'd0;
    always @(posedge clk) begin
        f_ovf_q <= ovf;
        f_cnt_q <= drop_count_o;
        if (f_rstd_q && !rst && !$past(rst)) begin
            assert (drop_o == f_ovf_q);
            if (f_ovf_q && f_cnt_q != 16'hFFFF) assert (drop_count_o == f_cnt_q + 1'b1);
            else                                 assert (drop_count_o == f_cnt_q);
        end
    end
`endif

endmodule
`default_nettype wire
