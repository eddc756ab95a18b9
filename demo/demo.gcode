; servoplot demo, streamed as a GRBL sender streams: one line per answer.
; The plotter has no pen lift, so the drawing is laid out to travel along its own baseline.
G21 G90
$$
; work origin 190 mm left of the machine origin, so the whole row fits the +-200 mm travel
G92 X190 Y0
F3000
; a square with rounded corners (G3 arcs)
G1 X5 Y0
G1 X45 Y0
G3 X50 Y5 I0 J5
G1 X50 Y45
G3 X45 Y50 I-5 J0
G1 X5 Y50
G3 X0 Y45 I0 J-5
G1 X0 Y5
G3 X5 Y0 I5 J0
; a five-pointed star inside it
G1 X10.31 Y4.77
G1 X25 Y45
G1 X39.69 Y4.77
G1 X2.47 Y32.29
G1 X47.53 Y32.29
G1 X10.31 Y4.77
G1 X5 Y0
?
; along the baseline: a circle, an ellipse, a sine and a function, each from the pen
G1 X70 Y0
$O R10 S270 F2400
G1 X95 Y0
$E A15 B8 S270 F2400
G1 X115 Y0
$S A6 W0.4 L60 F2400
$F X-30 U30 F2400 Y=12*exp(-x^2/150)
G92.1
G0 X0 Y-30
