// Byte-at-a-time COBS decoder for frames delimited by 0x00 (docs/protocol.md, Serial: COBS).
// Output stream: first marks a frame's first decoded byte; last pulses at the delimiter
// (err set when the frame was not valid COBS or the line had a framing error). Empty
// frames (delimiters back to back) produce nothing.
module cobs_decoder (
    input  wire       clk,
    input  wire       rst,
    input  wire       in_valid,
    input  wire [7:0] in_data,
    input  wire       in_err,     // UART framing error: poisons the current frame
    output reg        out_valid,
    output reg  [7:0] out_data,
    output reg        out_first,
    output reg        out_last,
    output reg        out_err
);
    reg [7:0] left;       // data bytes still to come in the current block
    reg       code255;    // current block's code was 255: no zero follows it
    reg       started;    // a code byte has been seen since the last delimiter
    reg       emitted;    // a byte was output for the current frame
    reg       bad;

    always @(posedge clk) begin
        out_valid <= 1'b0;
        out_first <= 1'b0;
        out_last <= 1'b0;
        out_err <= 1'b0;
        if (rst) begin
            left <= 0;
            code255 <= 1'b0;
            started <= 1'b0;
            emitted <= 1'b0;
            bad <= 1'b0;
        end else if (in_err) begin
            bad <= 1'b1;
        end else if (in_valid) begin
            if (in_data == 8'h00) begin
                if (started || bad) begin
                    out_last <= 1'b1;
                    out_err <= bad || (left != 0) || !emitted;
                end
                left <= 0;
                started <= 1'b0;
                emitted <= 1'b0;
                bad <= 1'b0;
            end else if (left == 0) begin  // a code byte
                if (started && !code255) begin  // the previous block ended in a zero
                    out_valid <= 1'b1;
                    out_data <= 8'h00;
                    out_first <= !emitted;
                    emitted <= 1'b1;
                end
                started <= 1'b1;
                left <= in_data - 1'b1;
                code255 <= (in_data == 8'hFF);
            end else begin
                out_valid <= 1'b1;
                out_data <= in_data;
                out_first <= !emitted;
                emitted <= 1'b1;
                left <= left - 1'b1;
            end
        end
    end
endmodule
