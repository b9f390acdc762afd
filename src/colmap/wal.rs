//! Reading a database in WAL mode without leaving `-wal` and `-shm` files beside it.
//!
//! COLMAP 3.8 and 4 both switch their databases to WAL mode. SQLite creates the two files when
//! any connection opens such a database, and deletes them when the last connection closes, but
//! only if that connection can write: a read-only connection leaves them behind. So a WAL database
//! is read through a read-write connection with `PRAGMA query_only`, which refuses every write
//! statement and still lets the close clean up. Databases with a rollback journal are opened
//! read-only as before (reading them creates no file).

use rusqlite::{Connection, OpenFlags};
use std::io::Read;
use std::path::Path;

/// Whether the file header says WAL mode (read and write versions, bytes 18 and 19, are 2).
pub fn is_wal(path: &Path) -> bool {
    let mut header = [0u8; 20];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut header))
        .is_ok_and(|()| header[18] == 2 && header[19] == 2)
}

/// Opens `path` for reading only (`extra` flags added): see the module docs.
pub fn open_for_reading(path: &Path, extra: OpenFlags) -> rusqlite::Result<Connection> {
    if !is_wal(path) {
        return Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY | extra);
    }
    let conn = Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE | extra)?;
    conn.pragma_update(None, "query_only", true)?;
    Ok(conn)
}
