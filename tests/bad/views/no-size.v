angle increment: 20
surface: l no-size.s 1
