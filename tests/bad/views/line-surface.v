angle increment: 45
surface: l line-surface.s 1.5
