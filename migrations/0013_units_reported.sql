-- A worker that resumes a job from a checkpoint older than its stored units (or from the
-- start, when it has none) computes those units again before it adds any: the coordinator
-- skips them, so the campaign's count stands still: 25–40 minutes for a 100-impact sample
-- at 48 per Dg on a shared core after a lost database. Each lease records the highest unit its worker has reported, stored or new; while
-- that is below the job's stored units (and its checkpoint's), the status shows the replay
-- left instead of no rate at all. A claim resets it.
ALTER TABLE jobs ADD COLUMN units_reported INTEGER NOT NULL DEFAULT 0;
