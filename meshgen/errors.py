"""meshgen's error for gear data that cannot be made."""


class GeometryError(ValueError):
    """Gear data that cannot be made (pointed or undercut teeth, a too wide face...). The message names the field
    of the gear data (as in a scenario's `gear:` block, e.g. gear.backlash_mm) and what is allowed."""
