angle increment: 20
surface: l /etc/passwd 1
