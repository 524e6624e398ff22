"""Level-0 safety reflexes."""

from easynav.recovery.diagnostic.reflexes.collision_safety_reflex import CollisionSafetyReflex

__all__ = ["CollisionSafetyReflex"]
