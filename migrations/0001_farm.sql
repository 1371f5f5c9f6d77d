-- The coordinator's state: campaigns, their cells and jobs, the per-impact series reported
-- by workers, and the latest checkpoint of each job. Times are Unix milliseconds.

CREATE TABLE campaigns (
    id              TEXT PRIMARY KEY,          -- uuid
    name            TEXT,
    spec            TEXT NOT NULL,             -- normalised campaign spec JSON
    samples         INTEGER NOT NULL,
    impacts_total   INTEGER NOT NULL,
    max_attempts    INTEGER NOT NULL,
    idempotency_key TEXT UNIQUE,
    created_ms      INTEGER NOT NULL,
    cancelled_ms    INTEGER
);

CREATE TABLE cells (
    campaign_id TEXT NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
    cell_index  INTEGER NOT NULL,
    angle_deg   REAL NOT NULL,
    shape       TEXT NOT NULL,
    swept       TEXT NOT NULL,                 -- JSON object of other swept values
    impacts     INTEGER NOT NULL,              -- planned per sample
    params      TEXT NOT NULL,                 -- grit_erosion::ImpactParams JSON of every job
    PRIMARY KEY (campaign_id, cell_index)
) WITHOUT ROWID;

-- state: queued | leased | done | failed | cancelled
CREATE TABLE jobs (
    id               INTEGER PRIMARY KEY,
    campaign_id      TEXT NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
    campaign_seq     INTEGER NOT NULL,         -- campaigns.rowid: older campaigns first
    cell_index       INTEGER NOT NULL,
    sample_index     INTEGER NOT NULL,
    seed             INTEGER NOT NULL,         -- u64 stored as its i64 bit pattern
    impacts_planned  INTEGER NOT NULL,
    impacts_done     INTEGER NOT NULL DEFAULT 0,
    state            TEXT NOT NULL DEFAULT 'queued',
    attempts         INTEGER NOT NULL DEFAULT 0, -- leases lost or failed
    lease_id         TEXT,
    worker           TEXT,
    lease_expires_ms INTEGER,
    last_error       TEXT,
    updated_ms       INTEGER NOT NULL,
    UNIQUE (campaign_id, cell_index, sample_index)
);
-- Claim order: oldest campaign, then sample 0 of every cell before sample 1, so partial
-- results cover every cell early.
CREATE INDEX jobs_queue ON jobs (state, campaign_seq, sample_index, cell_index);
CREATE INDEX jobs_leases ON jobs (state, lease_expires_ms);

-- One row per finished impact. `record` is the worker's ImpactRecord JSON, written with
-- round-trip float formatting so every f64 comes back bit for bit; the two REAL columns are
-- the same values for aggregation without parsing.
CREATE TABLE impacts (
    job_id        INTEGER NOT NULL REFERENCES jobs(id) ON DELETE CASCADE,
    impact        INTEGER NOT NULL,
    grain_mass_kg REAL NOT NULL,
    mass_loss_kg  REAL NOT NULL,
    record        TEXT NOT NULL,
    created_ms    INTEGER NOT NULL,
    PRIMARY KEY (job_id, impact)
) WITHOUT ROWID;
CREATE INDEX impacts_recent ON impacts (created_ms);

-- The latest checkpoint of each unfinished job.
CREATE TABLE checkpoints (
    job_id       INTEGER PRIMARY KEY REFERENCES jobs(id) ON DELETE CASCADE,
    impacts_done INTEGER NOT NULL,
    data         BLOB NOT NULL,
    updated_ms   INTEGER NOT NULL
);
