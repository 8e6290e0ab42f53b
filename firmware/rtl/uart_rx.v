// UART receiver, 8N1, LSB first. CLKS_PER_BIT = clock frequency / baud rate.
// Emits one byte per valid pulse; err pulses instead when the stop bit is 0 (framing error).
module uart_rx #(
    parameter CLKS_PER_BIT = 434
) (
    input  wire       clk,
    input  wire       rst,
    input  wire       rx,
    output reg        valid,
    output reg  [7:0] data,
    output reg        err
);
    localparam CW = $clog2(CLKS_PER_BIT + 1);
    localparam [31:0] BIT_LAST = CLKS_PER_BIT - 1;  // cut to CW bits where used: no width warning
    localparam [31:0] BIT_HALF = CLKS_PER_BIT / 2;
    reg [1:0] sync;
    reg [CW-1:0] timer;
    reg [3:0] bitn;
    reg busy;
    wire line = sync[1];

    always @(posedge clk) begin
        valid <= 1'b0;
        err <= 1'b0;
        if (rst) begin
            sync <= 2'b11;
            busy <= 1'b0;
            timer <= 0;
            bitn <= 0;
        end else begin
            sync <= {sync[0], rx};
            if (!busy) begin
                if (!line) begin  // start bit edge: sample it again half a bit later
                    busy <= 1'b1;
                    timer <= BIT_HALF[CW-1:0];
                    bitn <= 0;
                end
            end else if (timer != 0) begin
                timer <= timer - 1'b1;
            end else begin
                timer <= BIT_LAST[CW-1:0];
                bitn <= bitn + 1'b1;
                if (bitn == 0) begin
                    if (line) busy <= 1'b0;  // glitch, not a start bit
                end else if (bitn <= 8) begin
                    data <= {line, data[7:1]};
                end else begin
                    busy <= 1'b0;
                    valid <= line;
                    err <= !line;
                end
            end
        end
    end
endmodule
