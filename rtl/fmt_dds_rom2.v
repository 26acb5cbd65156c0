// fmt_dds_rom2 -- dual-port sine ROM shared by two DDS rows (one block RAM).
//
// Full-wave table of 2^TABLE_ADDR signed SINE_BITS words, entry i =
// round((2^(SINE_BITS-1) - 1) * sin(2*pi*i / 2^TABLE_ADDR)) (odd-symmetric, never
// -2^(SINE_BITS-1)).  Contents come from rtl/fmt_sine_rom_aAA_sSS.hex, written by
// `python -m fmt.generate` (`make lint` fails when it is stale).
// The file name is built from the two parameters; simulators that resolve $readmemh
// paths from their working directory get the folder through the macro FMT_ROM_DIR
// (e.g. -DFMT_ROM_DIR=\"/path/to/rtl/\"); Yosys and XST find it beside the source.
//
// Timing: synchronous read with two registers (the block RAM's output latch and its
// output register, which XST packs as DOA_REG/DOB_REG), both advancing only when
// ce = 1: data_x_o holds the word of the address present two ce edges ago.  clr_i
// (synchronous, at a ce edge) zeroes the output register (the block RAM's SSR).  Why a full-wave table and no quarter-wave folding: 1024 x 16 bit fits in
// one RAMB18 either way, and folding would cost an address and a sign adder per row.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_dds_rom2 #(
    parameter TABLE_ADDR = 10,               // table address bits (2^TABLE_ADDR entries, 1..99)
    parameter SINE_BITS  = `FMT_SINE_BITS    // table word width, signed (1..99)
) (
    input  wire                         clk,
    input  wire                         ce,        // sample strobe: read only when 1
    input  wire                         clr_i,     // zero the output registers at this ce edge
    input  wire [TABLE_ADDR-1:0]        addr_a_i,  // port A address (row 2p)
    input  wire [TABLE_ADDR-1:0]        addr_b_i,  // port B address (row 2p + 1)
    output reg  signed [SINE_BITS-1:0]  data_a_o,  // port A word, two registers
    output reg  signed [SINE_BITS-1:0]  data_b_o   // port B word, two registers
);

    // "fmt_sine_rom_aAA_sSS.hex" (24 characters; two decimal digits per number)
    localparam [7:0] A_TENS = 8'd48 + TABLE_ADDR / 10;
    localparam [7:0] A_ONES = 8'd48 + TABLE_ADDR % 10;
    localparam [7:0] S_TENS = 8'd48 + SINE_BITS / 10;
    localparam [7:0] S_ONES = 8'd48 + SINE_BITS % 10;
    localparam [8*24-1:0] FILE_NAME = {"fmt_sine_rom_a", A_TENS, A_ONES, "_s",
                                       S_TENS, S_ONES, ".hex"};

    reg [SINE_BITS-1:0] rom [0:(1 << TABLE_ADDR) - 1];

    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, FILE_NAME}, rom);
`else
        $readmemh(FILE_NAME, rom);
`endif
    end

    reg [SINE_BITS-1:0] rd_a_q, rd_b_q;   // block-RAM output latches

    always @(posedge clk) begin
        if (ce) begin
            rd_a_q <= rom[addr_a_i];
            rd_b_q <= rom[addr_b_i];
        end
    end

    always @(posedge clk) begin
        if (ce) begin
            if (clr_i) begin
                data_a_o <= {SINE_BITS{1'b0}};
                data_b_o <= {SINE_BITS{1'b0}};
            end else begin
                data_a_o <= rd_a_q;
                data_b_o <= rd_b_q;
            end
        end
    end

endmodule

`default_nettype wire
