// Two banks of DEPTH 32-bit words in one dual-port RAM: port A (loader) reads and writes
// either bank, port B (instruction processor) reads the active bank like the original
// design's $readmemh memory. INIT_FILE, if given, preloads bank 0 with $readmemh.
module program_memory #(
    parameter AW = 10,
    parameter INIT_FILE = ""
) (
    input  wire          clk,
    // port A: loader
    input  wire          a_we,
    input  wire [AW:0]   a_addr,     // {bank, word}
    input  wire [31:0]   a_wdata,
    output reg  [31:0]   a_rdata,
    // port B: instruction processor
    input  wire          b_clk,
    input  wire          b_bank,     // the loader's active bank
    input  wire [AW-1:0] b_addr,
    output reg  [31:0]   b_rdata
);
    reg [31:0] mem [0:(2 << AW) - 1];
    integer i;
    initial begin
        for (i = 0; i < (2 << AW); i = i + 1) mem[i] = 32'd0;
        if (INIT_FILE != "") $readmemh(INIT_FILE, mem, 0, (1 << AW) - 1);
    end

    always @(posedge clk) begin
        if (a_we) mem[a_addr] <= a_wdata;
        a_rdata <= mem[a_addr];
    end

    always @(posedge b_clk) b_rdata <= mem[{b_bank, b_addr}];
endmodule
