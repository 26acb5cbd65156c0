// fmt_fft_delay -- delay line of DEPTH samples for the SDF FFT stages.
//
// dout_o is din_i of DEPTH ce-steps earlier: the value written on the ce cycle t is
// read on the ce cycle t + DEPTH (dout_o is valid during that cycle, before its edge).
// Only ce cycles count.  The contents are not reset (a datapath memory; the FFT's valid
// flags mask what is read before it was written); rst only clears the ring pointer.
//
// DEPTH < RAM_MIN: a shift register (maps to SRLC32E with clock enable, or to flip-flops
//   when tiny).
// DEPTH >= RAM_MIN: a ring of DEPTH words with one write port and one registered read
//   port whose read address runs one ahead of the write address, so ring + read
//   register = DEPTH steps; it maps to LUT RAM or block RAM (simple dual port), cheaper
//   than SRLs from 8 words on (2 bits per LUT in a RAM32M).  DEPTH need not be a power
//   of two (the FFT's channel-interleaved lines are D x CH deep): the pointer then
//   wraps at DEPTH - 1 (one comparator more).  From BRAM_MIN words on the ring asks for
//   block RAM (ram_style attribute, Yosys and XST): Yosys maps a 96-deep line (N = 256,
//   CH = 3) to 3 LUT RAM banks plus read multiplexers, ~130 LUT6, otherwise.  A block-RAM
//   ring is read two steps ahead into the read latch and the block-RAM output register
//   (the same DEPTH steps in all); a shorter ring asks for LUT RAM.
// Latency: exactly DEPTH ce-steps (no extra register).
`default_nettype none
`include "fmt_defaults.vh"

module fmt_fft_delay #(
    parameter W       = 16,   // word width (bits)
    parameter DEPTH   = 8,    // delay in samples, >= 1
    parameter RAM_MIN = 8,    // depth from which the ring-buffer (RAM) form is used, >= 2
    parameter BRAM_MIN = 96   // depth from which the ring is put in block RAM
) (
    input  wire         clk,
    input  wire         rst,    // synchronous, active high: clears the ring pointer only
    input  wire         ce,     // sample strobe: one step per ce
    input  wire [W-1:0] din_i,  // word written this step
    output wire [W-1:0] dout_o  // word written DEPTH steps ago
);

    generate
        if (DEPTH >= RAM_MIN) begin : g_ram
            localparam AW = $clog2(DEPTH);
            reg [AW-1:0] wptr_q;
            reg [W-1:0]  rd_q;
            wire [AW-1:0] rptr;                   // the oldest word: written DEPTH-1 steps ago
            if ((1 << AW) == DEPTH) begin : g_pow2
                assign rptr = wptr_q + 1'b1;
            end else begin : g_mod
                localparam integer  TOP_I = DEPTH - 1;
                localparam [AW-1:0] TOP   = TOP_I[AW-1:0];
                assign rptr = (wptr_q == TOP) ? {AW{1'b0}} : wptr_q + 1'b1;
            end
            if (DEPTH >= BRAM_MIN) begin : g_bram
                // block RAM: read latch + output register, so the read address runs two
                // ahead of the write address (own pointer, no adder before the RAM)
                localparam integer  TOP_I = DEPTH - 1;
                localparam [AW-1:0] TOP   = TOP_I[AW-1:0];
                localparam integer  TWO_I = 2 % DEPTH;
                localparam [AW-1:0] TWO   = TWO_I[AW-1:0];
                (* ram_style = "block" *) reg [W-1:0] mem [0:DEPTH-1];
                reg [W-1:0]  lat_q;                // block-RAM read latch
                reg [AW-1:0] bptr_q;               // read address: written DEPTH-2 steps ago
                always @(posedge clk) begin
                    if (ce) begin
                        mem[wptr_q] <= din_i;
                        lat_q       <= mem[bptr_q];
                        rd_q        <= lat_q;      // block-RAM output register
                    end
                end
                always @(posedge clk) begin
                    if (rst)
                        bptr_q <= TWO;
                    else if (ce)
                        bptr_q <= (bptr_q == TOP) ? {AW{1'b0}} : bptr_q + 1'b1;
                end
            end else begin : g_lutram
                // LUT RAM (asynchronous read into rd_q): a block RAM here would need
                // its own output register (Yosys ECP5 picks block RAM for 64 deep)
                (* ram_style = "distributed" *) reg [W-1:0] mem [0:DEPTH-1];
                always @(posedge clk) begin
                    if (ce) begin
                        mem[wptr_q] <= din_i;
                        rd_q        <= mem[rptr];
                    end
                end
            end
            always @(posedge clk) begin
                if (rst)
                    wptr_q <= {AW{1'b0}};
                else if (ce)
                    wptr_q <= rptr;
            end
            assign dout_o = rd_q;
        end else if (DEPTH == 1) begin : g_reg
            reg [W-1:0] r_q;
            always @(posedge clk)
                if (ce) r_q <= din_i;
            assign dout_o = r_q;
        end else begin : g_srl
            reg [W*DEPTH-1:0] sr_q;   // sr_q[k*W +: W] = word written k+1 steps ago
            always @(posedge clk)
                if (ce) sr_q <= {sr_q[W*(DEPTH-1)-1:0], din_i};
            assign dout_o = sr_q[W*(DEPTH-1) +: W];
        end
    endgenerate

    // rst is only used by the ring form
    wire unused_ok = &{1'b0, rst};

endmodule

`default_nettype wire
