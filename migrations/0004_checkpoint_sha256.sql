-- The SHA-256 (lowercase hex) of each stored checkpoint's bytes, handed to the worker that
-- resumes from it, which starts the sample again from impact 0 when the bytes no longer match.
-- NULL for checkpoints stored before the column existed: the coordinator hashes them as read.
ALTER TABLE checkpoints ADD COLUMN sha256 TEXT;
