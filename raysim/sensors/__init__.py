"""Sensor models: each turns the scene into one sensor's raw output, chunk by chunk."""
