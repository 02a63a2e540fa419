angle factor: 0.5
