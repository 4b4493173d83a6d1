"""Pictures of a device: its skeleton (frames, links, mass centres) as data, an interactive HTML page and a PNG."""
