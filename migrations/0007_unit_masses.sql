-- What a cell's growth reads of each unit (docs/design.md, "Scenes"): the abrasive mass the
-- unit brought and the target mass it removed (kg/m), as the scene's `masses` gives them, so
-- judging a finished cell reads two numbers a unit instead of parsing every record in the
-- writer's transaction. NULL for a unit stored before this migration (its record is read
-- instead, giving the same bits) and for a scene whose cells do not grow.
ALTER TABLE units ADD COLUMN grain_kg_m REAL;
ALTER TABLE units ADD COLUMN loss_kg_m REAL;
