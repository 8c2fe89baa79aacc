from .navigators import NAVIGATORS, GeodesicNavigator, HarmonicNavigator

__all__ = ["NAVIGATORS", "GeodesicNavigator", "HarmonicNavigator"]
