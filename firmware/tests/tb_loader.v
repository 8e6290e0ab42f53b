// Simulation top for cocotb: rend3r_loader with its 50 MHz clock generated in Verilog
// (a clock toggled from Python costs two simulator callbacks per cycle).
`timescale 1ns / 1ps
module tb_loader #(
    parameter AW = 10,
    parameter CLKS_PER_BIT = 434
);
    reg           clk = 1'b0;
    reg           rst;
    reg           rmii_crs_dv;
    reg  [1:0]    rmii_rxd;
    reg           uart_rx;
    reg           prog_clk;
    reg  [AW-1:0] prog_addr;
    reg  [31:0]   frames_rendered;
    wire          rmii_tx_en;
    wire [1:0]    rmii_txd;
    wire          uart_tx;
    wire [31:0]   prog_data;
    wire          running, restart;
    wire [31:0]   active_words, malformed, loads;

    always #10 clk = ~clk;

    rend3r_loader #(.AW(AW), .CLKS_PER_BIT(CLKS_PER_BIT)) dut (
        .clk(clk), .rst(rst), .rmii_crs_dv(rmii_crs_dv), .rmii_rxd(rmii_rxd),
        .rmii_tx_en(rmii_tx_en), .rmii_txd(rmii_txd), .uart_rx(uart_rx), .uart_tx(uart_tx),
        .prog_clk(prog_clk), .prog_addr(prog_addr), .prog_data(prog_data),
        .frames_rendered(frames_rendered), .running(running), .restart(restart),
        .active_words(active_words), .malformed(malformed), .loads(loads));
endmodule
