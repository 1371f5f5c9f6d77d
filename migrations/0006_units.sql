-- One table of units for every scene (docs/design.md, "Scenes"): an impact of a sample and a
-- slice of a jet run are both a job's unit, stored as the scene's record JSON (round-trip
-- floats, so every f64 comes back bit for bit). `lost_kg_m` is the job's mass loss after the
-- unit, as the scene's record check returned it, so the next report's check starts from it
-- without reading every record. The columns that counted jet slices under impact names are
-- renamed for units, and a jet cell no longer stores the placeholders angle 90 and shape 'jet':
-- angle and shape are an impact cell's, NULL for a scene without them.
CREATE TABLE units (
    job_id     INTEGER NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
    unit       INTEGER NOT NULL,
    lost_kg_m  REAL NOT NULL,
    record     TEXT NOT NULL,
    created_ms INTEGER NOT NULL,
    PRIMARY KEY (job_id, unit)
) WITHOUT ROWID;
INSERT INTO units (job_id, unit, lost_kg_m, record, created_ms)
    SELECT job_id, impact,
           SUM(mass_loss_kg) OVER (PARTITION BY job_id ORDER BY impact ROWS UNBOUNDED PRECEDING),
           record, created_ms
    FROM impacts;
INSERT INTO units (job_id, unit, lost_kg_m, record, created_ms)
    SELECT job_id, slice, mass_loss_kg_m, record, created_ms FROM slices;
DROP TABLE impacts;
DROP TABLE slices;
CREATE INDEX units_recent ON units (created_ms);

ALTER TABLE campaigns RENAME COLUMN impacts_total TO units_total;
ALTER TABLE jobs RENAME COLUMN impacts_planned TO units_planned;
ALTER TABLE jobs RENAME COLUMN impacts_done TO units_done;
ALTER TABLE checkpoints RENAME COLUMN impacts_done TO units_done;

CREATE TABLE cells_units (
    campaign_id    TEXT NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
    cell_index     INTEGER NOT NULL,
    angle_deg      REAL,                      -- an impact cell's; NULL for other scenes
    shape          TEXT,                      -- an impact cell's; NULL for other scenes
    swept          TEXT NOT NULL,             -- JSON object of other swept values
    units          INTEGER NOT NULL,          -- planned per sample now
    params         TEXT NOT NULL,             -- the scene's parameters (JSON) of every job
    samples        INTEGER NOT NULL,          -- samples now
    units_max      INTEGER,                   -- units grow until steady, up to this
    units_step     INTEGER,
    samples_max    INTEGER,                   -- samples grow until the error bar is small
    target_sem_rel REAL,
    PRIMARY KEY (campaign_id, cell_index)
) WITHOUT ROWID;
INSERT INTO cells_units
    SELECT k.campaign_id, k.cell_index,
           CASE WHEN c.scene = 'impact' THEN k.angle_deg END,
           CASE WHEN c.scene = 'impact' THEN k.shape END,
           k.swept, k.impacts, k.params, k.samples, k.impacts_max, k.impacts_step,
           k.samples_max, k.target_sem_rel
    FROM cells k JOIN campaigns c ON c.id = k.campaign_id;
DROP TABLE cells;
ALTER TABLE cells_units RENAME TO cells;
