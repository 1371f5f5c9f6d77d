-- Engine pins (docs/operations.md, "Mixed machines"): a campaign records the fingerprint of
-- the engine that computes it (`grit version --json`: 16 hex digits of a canonical run's final
-- bits, one per scene), and only workers whose engine for the campaign's scene has that
-- fingerprint are leased its jobs, so no campaign mixes samples from engines that compute
-- different bits. Campaigns created before the pin keep NULL and are leased to any engine,
-- as they always were; their results say so by carrying no `engine`.
ALTER TABLE campaigns ADD COLUMN engine TEXT;
-- The commit of the grit that created the campaign ("unknown" without git at build time).
ALTER TABLE campaigns ADD COLUMN commit_id TEXT;
-- The fingerprints a worker last claimed with, as a JSON object from scene kind to fingerprint.
ALTER TABLE workers ADD COLUMN engines TEXT;
-- The fingerprint the lease holder claimed with for the job's scene, stamped on every unit it
-- reports.
ALTER TABLE jobs ADD COLUMN engine TEXT;
-- The fingerprint of the worker that computed the unit; NULL for units stored before the pin.
ALTER TABLE units ADD COLUMN engine TEXT;
