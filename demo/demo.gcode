; servoplot demo, streamed as a GRBL sender streams: one line per answer
G21 G90
$$
G1 X0 Y0 F3000
; a square with rounded corners (G2 arcs)
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
G0 X25 Y45
G1 X39.69 Y4.77
G1 X2.47 Y32.29
G1 X47.53 Y32.29
G1 X10.31 Y4.77
G1 X25 Y45
?
; the plotter's own curves: a circle, an ellipse, a sine and a function
G0 X70 Y25
$O R10 F2400
$E A15 B8 S180 F2400
G0 X60 Y-10
$S A6 W0.4 L60 F2400
G0 X60 Y-30
$F X-30 U30 F2400 Y=12*exp(-x^2/150)-6
G0 X0 Y0
