"""The report's figures, one module per kind (the only place, with :mod:`..plots` re-exporting
them, that imports matplotlib): :mod:`.common` holds the paper style and the drawing helpers
every figure shares, :mod:`.paths` the maps with paths, :mod:`.distances` the distance figures,
:mod:`.replay` the door-search replay, :mod:`.objects` object search's, :mod:`.chain` chained
searches' and :mod:`.indirect` indirect search's. Every figure is written by
:func:`.common._save`, looked up on the module at each call (``common._save``), so that one
patch of it intercepts them all."""
