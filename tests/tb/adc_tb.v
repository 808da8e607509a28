// Independent testbench for slotforge_top: one datasheet-timed AD7940 model per
// branch, and a log of what the design did.  It checks nothing itself; the
// Rust test (tests/icarus.rs) compares the log with lut-gen's schedule.
//
// Defines (from the test): NB branches, NM mux devices, WC channel bits,
// CLK_HALF clock half period in ns, CYCLES cycles to run, LOG log file name,
// RESET rising edges with rst high (default 6).
`timescale 1ns/1ps
`ifndef RESET
`define RESET 6
`endif
module adc_tb;
  reg clk = 1'b0;
  reg rst = 1'b1;
  wire [`NB-1:0] miso;
  wire [`NB-1:0] cs_n;
  wire [`NB-1:0] sclk;
  wire [3*`NB-1:0] mux_sel;
  wire [`NM-1:0] mux_en;
  wire sample_valid;
  wire [`WC-1:0] sample_channel;
  wire [13:0] sample_value;
  integer log;
  integer cycle = -1;
  integer edges = 0;
  reg [3*`NB-1:0] last_sel;
  reg [`NM-1:0] last_en;

  slotforge_top dut (
    .clk(clk), .rst(rst), .adc_miso(miso), .adc_cs_n(cs_n), .adc_sclk(sclk),
    .mux_sel(mux_sel), .mux_en(mux_en), .sample_valid(sample_valid),
    .sample_channel(sample_channel), .sample_value(sample_value)
  );

  always #(`CLK_HALF) clk = ~clk;

  // Cycle numbering of docs/timing.md: cycle 0 begins at the first rising edge
  // with rst sampled low.  Outputs are read 1 ns after each edge.
  always @(posedge clk) begin
    if (!rst || cycle >= 0) cycle <= cycle + 1;
  end

  // Rising edges from the first one (a reset edge): the mux pins are logged
  // at the first edge and whenever they change, reset or not, with the edge
  // that began cycle 0, so the log tells how long a value had been on the
  // pins at each conversion.
  always @(posedge clk) begin
    edges = edges + 1;
    #1;
    if (cycle == 0)
      $fdisplay(log, "CYCLE0 %0d", edges);
    if (edges == 1 || mux_sel !== last_sel || mux_en !== last_en)
      $fdisplay(log, "MUX %0d %0d %0d", edges, mux_sel, mux_en);
    last_sel = mux_sel;
    last_en = mux_en;
  end

  always @(posedge clk) begin
    #1;
    if (cycle >= 0 && sample_valid)
      $fdisplay(log, "SAMPLE %0d %0d %0d", cycle, sample_channel, sample_value);
  end

  genvar b;
  generate
    for (b = 0; b < `NB; b = b + 1) begin : adc
      reg out = 1'bz;
      reg [15:0] word;
      reg [13:0] code;
      reg cs_seen = 1'b1;
      integer falls;
      integer count = 0;
      assign miso[b] = out;
      // CS falling: sample the input (the code is a function of branch, mux
      // address and conversion count), drive the first leading zero within t3.
      always @(negedge cs_n[b]) begin
        code = b * 4099 + mux_sel[3*b +: 3] * 97 + mux_en * 811 + count * 131;
        word = {2'b00, code};
        count = count + 1;
        falls = 0;
        #5 out = 1'bx;
        #20 out = word[15];
      end
      // Each SCLK falling edge shifts the next bit out: invalid from 10 ns to
      // 80 ns after the edge, high-Z after the 16th.
      always @(negedge sclk[b]) begin
        if (!cs_n[b]) begin
          falls = falls + 1;
          #10 out = 1'bx;
          #70 out = (falls < 16) ? word[15 - falls] : 1'bz;
        end
      end
      // The log line of a conversion: its cycle, the mux address at the
      // sampling instant and the code the ADC will shift out.
      always @(posedge clk) begin
        #1;
        if (cycle >= 0 && cs_seen && !cs_n[b])
          $fdisplay(log, "CS %0d %0d %0d %0d %0d", b, cycle, mux_sel[3*b +: 3], mux_en, word[13:0]);
        cs_seen = cs_n[b];
      end
      always @(posedge cs_n[b]) begin
        #10 out = 1'bz;
      end
    end
  endgenerate

  initial begin
    log = $fopen(`LOG, "w");
    repeat (`RESET) @(posedge clk);
    @(negedge clk) rst = 1'b0;
    wait (cycle == `CYCLES);
    $fclose(log);
    $finish;
  end
endmodule
