-- Jet campaigns (docs/jet-campaigns.md): each campaign's scene, and the slices jet jobs
-- report. In a jet campaign the unit of progress is a slice of simulated time: the columns
-- named for impacts (campaigns.impacts_total, cells.impacts, jobs.impacts_planned and
-- impacts_done, checkpoints.impacts_done) count slices, cells.params holds
-- grit_erosion::jet::JetParams JSON, and cells.angle_deg and shape are 90 and 'jet' (the jet
-- hits the target straight on).
ALTER TABLE campaigns ADD COLUMN scene TEXT NOT NULL DEFAULT 'impact';

-- One row per finished slice. `record` is the worker's JetSlice JSON (round-trip floats, the
-- surface profile included); t_s and mass_loss_kg_m repeat two of its values for queries.
CREATE TABLE slices (
    job_id         INTEGER NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
    slice          INTEGER NOT NULL,
    t_s            REAL NOT NULL,
    mass_loss_kg_m REAL NOT NULL,
    record         TEXT NOT NULL,
    created_ms     INTEGER NOT NULL,
    PRIMARY KEY (job_id, slice)
) WITHOUT ROWID;
CREATE INDEX slices_recent ON slices (created_ms);
