"""The bench rigs of chapters 2-4 over USB serial: protocol, link, host drivers, emulators."""
