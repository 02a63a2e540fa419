angle increment: 20
surface: l broken-point.s 1
