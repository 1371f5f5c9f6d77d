-- Whether a cell grown by `until_steady` also waits for the damage balance
-- (`until_steady.balanced`; docs/erosion.md, "The damage balance"): 1 to grow a steady cell
-- until its last window's loss pays for the damage its impacts added, NULL or 0 as before.
ALTER TABLE cells ADD COLUMN units_balanced INTEGER;
