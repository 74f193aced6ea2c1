"""Classical identification from step and frequency responses (seeds 000, 002, 003)."""
