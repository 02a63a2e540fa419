0 2   0 2   0 0
CONTACT POINT  X: 1 Y: 0 Z: 0
END POINT  X: 1 Y: two Z: 0
