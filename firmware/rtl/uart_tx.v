// UART transmitter, 8N1, LSB first. Takes a byte when valid && ready.
module uart_tx #(
    parameter CLKS_PER_BIT = 434
) (
    input  wire       clk,
    input  wire       rst,
    input  wire       valid,
    input  wire [7:0] data,
    output wire       ready,
    output wire       tx
);
    localparam CW = $clog2(CLKS_PER_BIT + 1);
    localparam [31:0] BIT_LAST = CLKS_PER_BIT - 1;  // cut to CW bits where used: no width warning
    reg [9:0] shift;  // stop, data[7:0], start; shifted out LSB first
    reg [3:0] left;
    reg [CW-1:0] timer;

    assign ready = (left == 0);
    assign tx = (left == 0) ? 1'b1 : shift[0];

    always @(posedge clk) begin
        if (rst) begin
            left <= 0;
            timer <= 0;
            shift <= 10'h3FF;
        end else if (left == 0) begin
            if (valid) begin
                shift <= {1'b1, data, 1'b0};
                left <= 4'd10;
                timer <= BIT_LAST[CW-1:0];
            end
        end else if (timer != 0) begin
            timer <= timer - 1'b1;
        end else begin
            timer <= BIT_LAST[CW-1:0];
            shift <= {1'b1, shift[9:1]};
            left <= left - 1'b1;
        end
    end
endmodule
