"""EasyNav fault-injection plugins (FaultyController, FaultyLocalizer, FaultyPlanner,
FaultyMapsManager).
"""
