-- The damage each unit added to its target (kg/m, Σ m ΔD; docs/erosion.md, "The damage
-- balance"), as the scene's `masses` gives it beside the two masses of 0007, so that a growing
-- cell's steadiness can ask whether its loss pays for that damage without parsing records.
-- NULL where a unit's scene or the binary that stored it did not record it: such a unit's
-- cell is judged without the balance.
ALTER TABLE units ADD COLUMN damage_kg_m REAL;
