"""Buildings of our own: the demo, the office, the hospital, and numbered buildings generated from a layout
and a numbering scheme."""
