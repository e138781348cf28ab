#!/usr/bin/env python3
"""Writes a rosbag2 SQLite bag (a folder with metadata.yaml and bag_0.db3, the layout and tables
`ros2 bag record` makes up to Humble) from messages dumped by write_mcap.mjs --dump: their CDR
bytes come from @foxglove/rosmsg2-serialization, the database from Python's sqlite3. Nothing of
strata is used.

  write_db3.py DUMP OUT_DIR [--split N] [--compress message|file]
    --split: a new .db3 file every N messages
    --compress: zstd as `ros2 bag record --compression-format zstd` does it, by the zstd
      program: each message's data (compression_mode MESSAGE) or each whole file (FILE, the
      files then named .db3.zstd)
"""
import argparse
import json
import os
import sqlite3
import subprocess

SCHEMA = """
CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
                    serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,
                      timestamp INTEGER NOT NULL, data BLOB NOT NULL);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('dump')
    ap.add_argument('out')
    ap.add_argument('--split', type=int, default=0)
    ap.add_argument('--compress', choices=['message', 'file'])
    args = ap.parse_args()
    with open(os.path.join(args.dump, 'messages.jsonl')) as f:
        messages = [json.loads(line) for line in f if line.strip()]
    os.makedirs(args.out, exist_ok=True)
    per_file = args.split or len(messages)
    files, counts, counts_total = [], {}, 0
    for start in range(0, len(messages), per_file):
        name = 'bag_%d.db3' % len(files)
        files.append(name)
        db = sqlite3.connect(os.path.join(args.out, name))
        db.executescript(SCHEMA)
        db.execute("INSERT INTO schema VALUES (3, 'humble')")
        topic_ids = {}
        for m in messages[start:start + per_file]:
            if m['topic'] not in topic_ids:
                topic_ids[m['topic']] = len(topic_ids) + 1
                db.execute('INSERT INTO topics VALUES (?, ?, ?, ?, ?)',
                           (topic_ids[m['topic']], m['topic'], m['type'], 'cdr', ''))
            with open(os.path.join(args.dump, m['file']), 'rb') as f:
                data = f.read()
            if args.compress == 'message':
                # rosbag2's compressor declares each frame's size; a streamed frame does not:
                # every other message is written each way, so readers meet both.
                declared = ['--stream-size=%d' % len(data)] if counts_total % 2 == 0 else []
                data = subprocess.run(['zstd', '-q', '-c'] + declared, input=data,
                                      stdout=subprocess.PIPE, check=True).stdout
            counts_total += 1
            db.execute('INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)',
                       (topic_ids[m['topic']], int(m['t']), data))
            counts[(m['topic'], m['type'])] = counts.get((m['topic'], m['type']), 0) + 1
        db.commit()
        db.close()
        if args.compress == 'file':
            path = os.path.join(args.out, name)
            subprocess.run(['zstd', '-q', '--rm', path, '-o', path + '.zstd'], check=True)
            files[-1] = name + '.zstd'
    times = [int(m['t']) for m in messages]
    with open(os.path.join(args.out, 'metadata.yaml'), 'w') as f:
        f.write('rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n')
        f.write('  duration:\n    nanoseconds: %d\n' % (max(times) - min(times)))
        f.write('  starting_time:\n    nanoseconds_since_epoch: %d\n' % min(times))
        f.write('  message_count: %d\n  topics_with_message_count:\n' % len(messages))
        for (topic, type_), n in sorted(counts.items()):
            f.write('    - topic_metadata:\n        name: %s\n        type: %s\n'
                    '        serialization_format: cdr\n        offered_qos_profiles: ""\n'
                    '      message_count: %d\n' % (topic, type_, n))
        if args.compress:
            f.write('  compression_format: zstd\n  compression_mode: %s\n'
                    % args.compress.upper())
        else:
            f.write('  compression_format: ""\n  compression_mode: ""\n')
        f.write('  relative_file_paths:\n')
        for name in files:
            f.write('    - %s\n' % name)
        f.write('  files:\n')
        for name in files:
            f.write('    - path: %s\n' % name)


if __name__ == '__main__':
    main()
