; A file as vpype writes it, for a plotter with a pen lift on M3/M5 ($213=1): lower the pen
; for each stroke, raise it for the travel to the next. The simulator's plot.svg draws the
; strokes in black and the pen-up travel dashed.
$213=1
G21
G90
G0 X10 Y10
M3
G1 X40 Y10 F3000
G1 X40 Y30
G1 X10 Y30
G1 X10 Y10
M5
G0 X60 Y20
M3
G2 X60 Y20 I10 J0
M5
G0 X0 Y0
M2
