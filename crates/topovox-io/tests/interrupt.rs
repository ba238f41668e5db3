//! What the CLI's signal handler does: removing the temporaries this
//! process is writing. In a file of its own (its own process): it removes
//! every live temporary of the process, which would break other tests
//! writing at the same time.

#![cfg(unix)]

mod common;

use common::{leftovers, scratch};

#[test]
fn live_temporaries_are_removed_on_request() {
    let d = scratch("live");
    let out = d.join("big.txt");
    let seen = std::sync::Mutex::new(Vec::new());
    let r = topovox_io::atomic::write_atomically(&out, |w| {
        w.write_all(b"partial")?;
        w.flush()?;
        seen.lock().unwrap().extend(leftovers(&d));
        // What the CLI's signal handler does, mid-write.
        topovox_io::atomic::remove_live_temporaries(None);
        seen.lock().unwrap().push(format!("after: {:?}", leftovers(&d)));
        Err(std::io::Error::other("interrupted"))
    });
    assert!(r.is_err());
    let seen = seen.into_inner().unwrap();
    assert_eq!(seen.len(), 2, "{seen:?}");
    assert!(seen[0].starts_with(".big.txt.topovox-tmp-"), "{seen:?}");
    assert_eq!(seen[1], "after: []");
    assert!(!out.exists());
}
