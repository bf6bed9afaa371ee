"""Reference implementations that discsim is measured against (never imported by discsim)."""
