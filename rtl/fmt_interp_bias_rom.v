// fmt_interp_bias_rom -- bias-correction table of the paraboloid fits, 512 x 8 bit,
// registered read (1 clock cycle).  Address {fit, |offset|}: fit = 1 Moore, 0 Von
// Neumann; |offset| in 1/256 cell (0..128); data = corrected |offset| (0..128).
// Contents rtl/fmt_interp_bias.hex from `python -m fmt.interp --write-hex` (the inverse
// of the mean fitted-offset curve of an 8 mm disk contact on the 5 mm pitch; see
// sim/fmt/interp.py).  Twin: fmt.interp.bias_table.
`default_nettype none
`include "fmt_defaults.vh"

module fmt_interp_bias_rom (
    input  wire       clk,    // processing clock
    input  wire [8:0] addr_i, // {fit, |offset|[7:0]}
    output reg  [7:0] data_o  // corrected |offset|, one cycle later
);
    reg [7:0] rom [0:511];
    initial begin
`ifdef FMT_ROM_DIR
        $readmemh({`FMT_ROM_DIR, "fmt_interp_bias.hex"}, rom);
`else
        $readmemh("fmt_interp_bias.hex", rom);
`endif
    end
    always @(posedge clk) data_o <= rom[addr_i];
endmodule
`default_nettype wire
