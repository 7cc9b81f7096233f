//! Requests a newer one supersedes. The page names the view each request fills, in the header
//! `X-Specula-View` (its own random id and the view's name, such as `k3f9/environment-pow`);
//! a request whose view has since been asked again gives up when its turn to compute comes,
//! answering 409 at once, instead of computing an image nobody will see. The browser's abort
//! alone would not do it: the server hears of a closed connection only when it writes, after
//! the work. A computation already running finishes (each is bounded: the largest explorer
//! view takes well under a second here), so a new request waits for one at most.
//!
//! Requests without the header (a script, `curl`) are never superseded.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use axum::extract::{Request, State};
use axum::middleware::Next;
use axum::response::Response;

/// The header naming a request's view.
pub const VIEW_HEADER: &str = "x-specula-view";
/// The longest view name kept; a longer one is not tracked.
const MAX_VIEW_BYTES: usize = 96;
/// Views tracked at most: past it the record starts again (a page then loses one chance
/// to skip stale work, nothing more).
const MAX_VIEWS: usize = 512;

/// The latest request of each view.
#[derive(Clone, Default)]
pub struct Views(Arc<Mutex<HashMap<String, Arc<AtomicU64>>>>);

/// One request's place among its view's.
#[derive(Clone)]
struct Ticket {
    latest: Arc<AtomicU64>,
    mine: u64,
}

tokio::task_local! {
    static TICKET: Option<Ticket>;
}

impl Views {
    fn ticket(&self, view: &str) -> Option<Ticket> {
        if view.is_empty() || view.len() > MAX_VIEW_BYTES {
            return None;
        }
        let mut views = self
            .0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if views.len() >= MAX_VIEWS && !views.contains_key(view) {
            views.clear();
        }
        let latest = Arc::clone(views.entry(view.to_owned()).or_default());
        let mine = latest.fetch_add(1, Ordering::SeqCst) + 1;
        Some(Ticket { latest, mine })
    }
}

/// Runs the request with its ticket, where it names a view.
pub async fn track(State(views): State<Views>, request: Request, next: Next) -> Response {
    let ticket = request
        .headers()
        .get(VIEW_HEADER)
        .and_then(|value| value.to_str().ok())
        .and_then(|view| views.ticket(view));
    TICKET.scope(ticket, next.run(request)).await
}

/// Whether a newer request has asked for this request's view.
#[must_use]
pub fn superseded() -> bool {
    TICKET
        .try_with(|ticket| {
            ticket
                .as_ref()
                .is_some_and(|t| t.latest.load(Ordering::SeqCst) != t.mine)
        })
        .unwrap_or(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn a_newer_request_of_the_same_view_supersedes_an_older_one_only() {
        let views = Views::default();
        let first = views.ticket("page/environment");
        let other = views.ticket("page/volume");
        let check = |ticket: Option<Ticket>| TICKET.scope(ticket, async { superseded() });
        assert!(!check(first.clone()).await);
        let second = views.ticket("page/environment");
        assert!(check(first).await, "the older request of the view");
        assert!(!check(second).await, "the newer one");
        assert!(!check(other).await, "another view");
        assert!(!check(None).await, "a request naming no view");
        assert!(views.ticket(&"x".repeat(MAX_VIEW_BYTES + 1)).is_none());
        assert!(!superseded(), "outside any request");
    }
}
