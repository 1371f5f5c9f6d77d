-- Cells whose impacts grow until steady, or whose samples grow until the error bar is small
-- (docs/erosion.md, "Extending a cell"). `cells.impacts` is the current plan per sample, and
-- `cells.samples` the current number of samples; the rule columns are NULL for fixed plans.
ALTER TABLE cells ADD COLUMN samples INTEGER NOT NULL DEFAULT 0;
UPDATE cells SET samples = (SELECT samples FROM campaigns WHERE campaigns.id = cells.campaign_id);
ALTER TABLE cells ADD COLUMN impacts_max INTEGER;
ALTER TABLE cells ADD COLUMN impacts_step INTEGER;
ALTER TABLE cells ADD COLUMN samples_max INTEGER;
ALTER TABLE cells ADD COLUMN target_sem_rel REAL;
