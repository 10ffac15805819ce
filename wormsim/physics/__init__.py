"""The physics every level shares: gear_theory (DIN 3975 sizes, efficiency, forces), friction (mu and the friction
angle), locking (self-locking as a result), geometry (the edge to meshgen), validate (checks beyond the schema) and
units (user units to SI and back)."""
