; Hard limits on, the e-stop wired; a line, then a circle that passes x = 50 mm.
$21=1
$208=1
G1 X20 Y0 F1200
G2 X20 Y0 I20 J0
G1 X0 Y0
