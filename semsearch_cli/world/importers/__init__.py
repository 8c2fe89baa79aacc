"""Importers: maps of other tools (ROS map_server, KTH floor plans, MobileSim) as scenario folders."""
