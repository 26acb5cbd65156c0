// fmt_interp_bias_rom -- offset tables of the fits, 1024 x 8 bit block-RAM ROM, read
// data registered (2 clock cycles: the block RAM's read register, then its output
// register).  Address {kind[1:0], index[7:0]}: kind 0 Von Neumann bias correction,
// 1 Moore bias correction (index = fitted |offset| in 1/256 cell, 0..128), 2 one-sided
// edge estimate (index = floor(256 * neighbour / centre), 0..255), 3 unused (zeros);
// data = |offset| in 1/256 cell (0..128).  Contents rtl/fmt_interp_bias.hex from
// `python -m fmt.generate` (inverse curves of an 8 mm disk contact on the
// 5 mm pitch; see sim/fmt/interp.py).  Twin: fmt.interp.bias_table / edge_table.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_bias_rom (
    input  wire       clk,    // processing clock
    input  wire [9:0] addr_i, // {kind[1:0], index[7:0]}
    output reg  [7:0] data_o  // corrected |offset|, two cycles later
);
    (* rom_style = "block" *)
    reg [7:0] rom [0:1023];
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, "fmt_interp_bias.hex"}, rom);
`else
        $readmemh("fmt_interp_bias.hex", rom);
`endif
    end
    reg [7:0] rd_q;
    always @(posedge clk) begin
        rd_q   <= rom[addr_i];
        data_o <= rd_q;
    end
endmodule
`default_nettype wire
