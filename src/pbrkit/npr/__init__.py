"""Non-photorealistic styles on top of physically based shading: toon bands, outlines, hatching."""
