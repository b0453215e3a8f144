//! The Hub's HTTP API, as much of it as a dataset download needs: the commit a revision
//! names, the recursive file listing, and each file's content. Every request has a
//! connect timeout and a read timeout (`Settings`); every file is checked against the
//! size and hash the listing states (the SHA-256 of LFS files, the git blob SHA-1 of the
//! others) and the ETag the server sends with it, before it is renamed into `blobs/`.

use crate::cache::{Entry, Hasher, RepoCache};
use crate::Settings;
use futures_util::StreamExt;
use reqwest::header::{HeaderMap, HeaderValue, AUTHORIZATION, LINK};
use reqwest::{Client, StatusCode};
use serde::Deserialize;
use std::io::Write;
use std::time::Duration;

/// Why a request failed.
#[derive(Debug)]
pub enum RemoteError {
    NotFound(String),
    Unauthorized(String),
    /// No connection, a timeout, a 5xx/429 answer: the Hub is unreachable or failing.
    Unreachable(String),
    /// The server answered, but with something that cannot be right (a file whose size or
    /// hash differs from what the listing states, an unreadable listing).
    Bad(String),
}

impl std::fmt::Display for RemoteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RemoteError::NotFound(s)
            | RemoteError::Unauthorized(s)
            | RemoteError::Unreachable(s)
            | RemoteError::Bad(s) => f.write_str(s),
        }
    }
}

fn request_error(url: &str, e: reqwest::Error, timeout: Duration) -> RemoteError {
    if e.is_timeout() {
        RemoteError::Unreachable(format!(
            "{url}: no answer within {} s (HF_HUB_ETAG_TIMEOUT / HF_HUB_DOWNLOAD_TIMEOUT)",
            timeout.as_secs_f64()
        ))
    } else {
        let mut text = e.to_string();
        let mut source = std::error::Error::source(&e);
        while let Some(s) = source {
            text.push_str(&format!(": {s}"));
            source = s.source();
        }
        RemoteError::Unreachable(format!("{url}: {text}"))
    }
}

/// A Hub client for one repository.
pub struct Remote {
    endpoint: String,
    repo_id: String,
    metadata: Client,
    download: Client,
    settings: Settings,
}

#[derive(Deserialize)]
struct RevisionInfo {
    sha: Option<String>,
}

#[derive(Deserialize)]
struct TreeEntry {
    #[serde(rename = "type")]
    kind: String,
    path: String,
    #[serde(default)]
    size: u64,
    #[serde(default)]
    oid: String,
    lfs: Option<Lfs>,
}

#[derive(Deserialize)]
struct Lfs {
    oid: String,
    size: u64,
}

fn client(timeout: Duration, token: Option<&str>) -> Result<Client, String> {
    let mut headers = HeaderMap::new();
    if let Some(t) = token {
        let mut v = HeaderValue::from_str(&format!("Bearer {t}"))
            .map_err(|_| "HF_TOKEN holds characters not allowed in a header".to_string())?;
        v.set_sensitive(true);
        headers.insert(AUTHORIZATION, v);
    }
    Client::builder()
        .connect_timeout(timeout)
        .read_timeout(timeout)
        .default_headers(headers)
        .user_agent(concat!("rh-hub/", env!("CARGO_PKG_VERSION")))
        .build()
        .map_err(|e| format!("cannot set up the HTTP client: {e}"))
}

impl Remote {
    pub fn new(endpoint: &str, repo_id: &str, settings: &Settings) -> Result<Remote, String> {
        let token = crate::token();
        Ok(Remote {
            endpoint: endpoint.to_string(),
            repo_id: repo_id.to_string(),
            metadata: client(settings.metadata_timeout, token.as_deref())?,
            download: client(settings.download_timeout, token.as_deref())?,
            settings: settings.clone(),
        })
    }

    /// Sends a GET and classifies a failing status.
    async fn get(
        &self,
        client: &Client,
        url: &str,
        timeout: Duration,
    ) -> Result<reqwest::Response, RemoteError> {
        let response = client
            .get(url)
            .send()
            .await
            .map_err(|e| request_error(url, e, timeout))?;
        let status = response.status();
        if status.is_success() {
            return Ok(response);
        }
        let message = response
            .headers()
            .get("x-error-message")
            .and_then(|v| v.to_str().ok())
            .map(|s| format!(" ({s})"))
            .unwrap_or_default();
        let text = format!("{url}: HTTP {status}{message}");
        Err(match status {
            StatusCode::NOT_FOUND => RemoteError::NotFound(text),
            StatusCode::UNAUTHORIZED | StatusCode::FORBIDDEN => RemoteError::Unauthorized(text),
            s if s.is_server_error() || s == StatusCode::TOO_MANY_REQUESTS => {
                RemoteError::Unreachable(text)
            }
            _ => RemoteError::Bad(text),
        })
    }

    async fn get_json<T: for<'de> Deserialize<'de>>(
        &self,
        url: &str,
    ) -> Result<(T, Option<String>), RemoteError> {
        let response = self
            .get(&self.metadata, url, self.settings.metadata_timeout)
            .await?;
        let next = response
            .headers()
            .get(LINK)
            .and_then(|v| v.to_str().ok())
            .and_then(next_link);
        let body = response
            .bytes()
            .await
            .map_err(|e| request_error(url, e, self.settings.metadata_timeout))?;
        let value = serde_json::from_slice(&body)
            .map_err(|e| RemoteError::Bad(format!("{url}: unreadable answer: {e}")))?;
        Ok((value, next))
    }

    /// The commit `revision` names.
    pub async fn commit(&self, revision: &str) -> Result<String, RemoteError> {
        let url = format!(
            "{}/api/datasets/{}/revision/{}",
            self.endpoint,
            self.repo_id,
            encode(revision)
        );
        let (info, _): (RevisionInfo, _) = self.get_json(&url).await?;
        info.sha
            .filter(|s| crate::cache::is_commit(s))
            .ok_or_else(|| RemoteError::Bad(format!("{url}: the answer names no commit")))
    }

    /// Every file of the repository at `commit`, with the size and hash it must have.
    pub async fn files(&self, commit: &str) -> Result<Vec<Entry>, RemoteError> {
        let mut url = format!(
            "{}/api/datasets/{}/tree/{commit}?recursive=true&expand=false",
            self.endpoint, self.repo_id
        );
        let mut entries = Vec::new();
        for _page in 0..100_000 {
            let (page, next): (Vec<TreeEntry>, _) = self.get_json(&url).await?;
            for e in page.into_iter().filter(|e| e.kind == "file") {
                let (blob, size) = match e.lfs {
                    Some(lfs) => (lfs.oid, lfs.size),
                    None => (e.oid, e.size),
                };
                if !crate::cache::is_hash_name(&blob)
                    || e.path.split('/').any(|p| p == ".." || p.is_empty())
                {
                    return Err(RemoteError::Bad(format!(
                        "{url}: file entry '{}' has no usable hash or path",
                        e.path
                    )));
                }
                entries.push(Entry {
                    path: e.path,
                    size,
                    blob: blob.to_ascii_lowercase(),
                });
            }
            match next {
                Some(n) => url = n,
                None => {
                    entries.sort_by(|a, b| a.path.cmp(&b.path));
                    return Ok(entries);
                }
            }
        }
        Err(RemoteError::Bad(format!("{url}: the listing never ends")))
    }

    /// Downloads one file into `blobs/<hash>`, checking size, hash and ETag on the way;
    /// nothing that fails a check is left in `blobs/`.
    pub async fn download(
        &self,
        cache: &RepoCache,
        commit: &str,
        entry: &Entry,
    ) -> Result<(), RemoteError> {
        let url = format!(
            "{}/datasets/{}/resolve/{commit}/{}",
            self.endpoint,
            self.repo_id,
            entry
                .path
                .split('/')
                .map(encode)
                .collect::<Vec<_>>()
                .join("/")
        );
        let timeout = self.settings.download_timeout;
        let mut response = self.get(&self.download, &url, timeout).await?;
        // The server's own statement of the content's hash, when it gives one.
        let etag = ["x-linked-etag", "etag"].iter().find_map(|h| {
            let v = response.headers().get(*h)?.to_str().ok()?;
            let v = v
                .trim()
                .trim_start_matches("W/")
                .trim_matches('"')
                .to_ascii_lowercase();
            crate::cache::is_hash_name(&v).then_some(v)
        });
        if let Some(etag) = &etag {
            if *etag != entry.blob {
                return Err(RemoteError::Bad(format!(
                    "{}: the server sends ETag {etag}, but the file listing states {} for it",
                    entry.path, entry.blob
                )));
            }
        }
        let blob = cache.blob_path(&entry.blob);
        let dir = blob.parent().expect("blobs/ folder");
        std::fs::create_dir_all(dir)
            .map_err(|e| RemoteError::Bad(format!("{}: {e}", dir.display())))?;
        let tmp = dir.join(format!("{}.{}.incomplete", entry.blob, std::process::id()));
        let result = async {
            let mut file = std::fs::File::create(&tmp)
                .map_err(|e| RemoteError::Bad(format!("{}: {e}", tmp.display())))?;
            let mut hasher = Hasher::new(entry.size);
            while let Some(chunk) = response
                .chunk()
                .await
                .map_err(|e| request_error(&url, e, timeout))?
            {
                hasher.update(&chunk);
                if hasher.len() > entry.size {
                    break;
                }
                file.write_all(&chunk)
                    .map_err(|e| RemoteError::Bad(format!("{}: {e}", tmp.display())))?;
            }
            file.sync_all().ok();
            let got_len = hasher.len();
            let (sha256, sha1) = hasher.finish();
            let got = if entry.blob.len() == 64 { sha256 } else { sha1 };
            if got_len != entry.size || got != entry.blob {
                return Err(RemoteError::Bad(format!(
                    "{} from {url} is corrupt: the Hub states {} bytes with hash {}, it served {}{} bytes with hash {got}; not stored",
                    entry.path,
                    entry.size,
                    entry.blob,
                    if got_len > entry.size { "more than " } else { "" },
                    got_len
                )));
            }
            std::fs::rename(&tmp, &blob).map_err(|e| RemoteError::Bad(format!("{}: {e}", blob.display())))
        }
        .await;
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result
    }

    /// Downloads every entry whose blob is absent or does not match its name; links them
    /// all into the snapshot. Prints progress to stderr when there is much to fetch.
    pub async fn download_all(
        &self,
        cache: &RepoCache,
        commit: &str,
        entries: &[Entry],
    ) -> Result<usize, RemoteError> {
        let mut todo = Vec::new();
        let mut seen = std::collections::BTreeSet::new();
        for e in entries {
            // Files with the same content share one blob: fetch it once.
            if !seen.insert(e.blob.as_str()) {
                continue;
            }
            let blob = cache.blob_path(&e.blob);
            let good =
                blob.exists() && crate::cache::content_matches(&blob, &e.blob).unwrap_or(false);
            if !good {
                if blob.exists() {
                    rh_contract::note!(
                        "{}: cached blob {} does not match its hash; fetching it again",
                        e.path,
                        e.blob
                    );
                    let _ = std::fs::remove_file(&blob);
                }
                todo.push(e);
            }
        }
        let total = todo.len();
        let mut done = 0usize;
        let mut stream =
            futures_util::stream::iter(todo.iter().map(|e| self.download(cache, commit, e)))
                .buffer_unordered(self.settings.concurrent_downloads.max(1));
        // Every started download runs to its end (a failure removes its own temporary);
        // the first failure is reported.
        let mut first_error = None;
        while let Some(result) = stream.next().await {
            if let Err(e) = result {
                first_error.get_or_insert(e);
                continue;
            }
            done += 1;
            if total >= 50 && (done * 10 / total) != ((done - 1) * 10 / total) {
                rh_contract::note!("downloaded {done}/{total} files");
            }
        }
        drop(stream);
        if let Some(e) = first_error {
            return Err(e);
        }
        for e in entries {
            cache.link(commit, e).map_err(|err| {
                RemoteError::Bad(format!("cannot link {} in the cache: {err}", e.path))
            })?;
        }
        Ok(total)
    }
}

/// The `rel="next"` address of a `Link` header.
fn next_link(header: &str) -> Option<String> {
    header.split(',').find_map(|part| {
        let (url, params) = part.split_once(';')?;
        params.contains("rel=\"next\"").then(|| {
            url.trim()
                .trim_start_matches('<')
                .trim_end_matches('>')
                .to_string()
        })
    })
}

/// Percent-encodes a path segment or revision (`refs/pr/1` keeps no slash).
fn encode(s: &str) -> String {
    s.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_and_encoding() {
        assert_eq!(
            next_link("<https://h/api/x?cursor=a>; rel=\"next\"").as_deref(),
            Some("https://h/api/x?cursor=a")
        );
        assert_eq!(next_link("<https://h/a>; rel=\"prev\""), None);
        assert_eq!(encode("refs/pr/1"), "refs%2Fpr%2F1");
        assert_eq!(encode("a b.json"), "a%20b.json");
    }
}
