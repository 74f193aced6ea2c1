"""The simulator side: the model library, deck building blocks, and the simulator backends."""
