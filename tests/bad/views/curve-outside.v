angle increment: 20
curve: ../curve.dat 10
