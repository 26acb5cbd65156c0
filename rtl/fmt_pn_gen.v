// fmt_pn_gen -- pseudo-noise chip generator shared by the row modulators ("stir")
// and the column despreaders ("unstir").
//
// A Fibonacci LFSR of PN_BITS bits (feedback = XOR of the bits selected by TAPS,
// shifted in at bit 0, output = bit PN_BITS-1) steps once every chip_len samples.
// The default polynomial x^15 + x^14 + 1 (TAPS = 15'h6000) is maximal: period
// 2^15 - 1 chips.  The LFSR is loaded with SEED at reset and free-runs; `enable`
// only gates the sign that leaves the block (PN off = sign +1 everywhere) so turning
// the PN on and off never misaligns transmit and receive.
//
// tx_sign_o is the transmit sign (1 = multiply by -1) of the current sample.
// rx_sign_o is the same sequence delayed by rx_delay_i samples (0 = no delay,
// at most 2^DELAY_W - 1), to line up with the channel delay in front of the ADC.
// Everything advances on the sample strobe ce (one sample per ce edge; ce = 1 steps on
// every clk): sample i after reset is the i-th ce edge with rst low, and the outputs,
// registered, change only at ce edges (constant over the clk cycles of a sample).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_pn_gen #(
    parameter PN_BITS = `FMT_PN_BITS,   // LFSR length L (period 2^L - 1 chips)
    parameter TAPS    = 15'h6000,       // feedback taps mask, PN_BITS wide (maximal for L = 15)
    parameter SEED    = 1,              // non-zero reset state of the LFSR
    parameter CHIP_W  = 10,             // width of the chip-length setting (samples per chip)
    parameter DELAY_W = 6               // width of the receive-delay setting
) (
    input  wire               clk,
    input  wire               rst,          // synchronous, active high
    input  wire               ce,           // sample strobe: the generator steps on ce
    input  wire               enable_i,     // 0: PN off, both signs stay +1
    input  wire [CHIP_W-1:0]  chip_len_i,   // samples per chip; 0 is taken as 1
    input  wire [DELAY_W-1:0] rx_delay_i,   // receive delay in samples
    output reg                tx_sign_o,    // 1 = invert (transmit side)
    output reg                rx_sign_o,    // 1 = invert (receive side, delayed)
    output reg                chip_start_o  // 1 on the first sample of each chip
);

    localparam DEPTH = 1 << DELAY_W;

    reg [PN_BITS-1:0] lfsr_q;
    reg [CHIP_W-1:0]  count_q;
    reg [DEPTH-1:0]   history_q;   // history_q[k] = tx sign of k samples ago

    wire [CHIP_W-1:0] last_count = (chip_len_i == {CHIP_W{1'b0}}) ? {CHIP_W{1'b0}}
                                                                 : chip_len_i - 1'b1;
    wire              chip_end   = (count_q >= last_count);
    wire              feedback   = ^(lfsr_q & TAPS[PN_BITS-1:0]);
    wire              sign_now   = enable_i & lfsr_q[PN_BITS-1];

    always @(posedge clk) begin
        if (rst) begin
            lfsr_q       <= SEED[PN_BITS-1:0];
            count_q      <= {CHIP_W{1'b0}};
            history_q    <= {DEPTH{1'b0}};
            tx_sign_o    <= 1'b0;
            rx_sign_o    <= 1'b0;
            chip_start_o <= 1'b0;
        end else if (ce) begin
            if (chip_end) begin
                count_q <= {CHIP_W{1'b0}};
                lfsr_q  <= {lfsr_q[PN_BITS-2:0], feedback};
            end else begin
                count_q <= count_q + 1'b1;
            end
            history_q    <= {history_q[DEPTH-2:0], sign_now};
            tx_sign_o    <= sign_now;
            rx_sign_o    <= (rx_delay_i == {DELAY_W{1'b0}}) ? sign_now
                                                            : history_q[rx_delay_i - 1'b1];
            chip_start_o <= (count_q == {CHIP_W{1'b0}});
        end
    end

`ifdef FORMAL
    // Formal properties (SymbiYosys, formal/fmt_pn_gen.sby; never seen by synthesis).
    reg past_valid_q = 1'b0;
    always @(posedge clk) past_valid_q <= 1'b1;
    always @(*) if (!past_valid_q) assume (rst);
    always @(posedge clk) begin
        if (past_valid_q && !$past(rst)) begin
            // the LFSR never reaches the all-zero lock-up state
            assert (lfsr_q != {PN_BITS{1'b0}});
            // the newest history entry is the transmit sign (inductive invariant)
            assert (history_q[0] == tx_sign_o);
            // no sample strobe: nothing moves
            if (!$past(ce))
                assert (lfsr_q == $past(lfsr_q) && count_q == $past(count_q) &&
                        history_q == $past(history_q) && tx_sign_o == $past(tx_sign_o) &&
                        rx_sign_o == $past(rx_sign_o) && chip_start_o == $past(chip_start_o));
            // PN off: the transmit sign is +1
            if ($past(ce) && !$past(enable_i)) assert (!tx_sign_o);
            // zero receive delay: receive and transmit signs are the same sample
            if ($past(ce) && $past(rx_delay_i) == {DELAY_W{1'b0}}) assert (rx_sign_o == tx_sign_o);
            // one receive-delay step: rx is tx of the previous sample (the value tx held
            // before this sample's ce edge)
            if ($past(ce) && $past(rx_delay_i) == 1) assert (rx_sign_o == $past(tx_sign_o));
            // the chip counter never runs past a chip while the setting is constant
            if ($past(chip_len_i) == chip_len_i && $past(count_q) < last_count)
                assert (count_q <= last_count);
        end
        if (past_valid_q && $past(rst)) assert (lfsr_q == SEED[PN_BITS-1:0] && !tx_sign_o);
    end
`endif

endmodule

`default_nettype wire
