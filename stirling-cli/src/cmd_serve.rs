//! `stirling serve`: the interactive teaching page on localhost (docs/user-guide.md, "The
//! interactive page"). One thread takes the requests; each is computed on a worker thread
//! within a deadline, every computation is bounded (n <= 50, limit cycle over at most 10 s
//! of simulated time, a declaration sent from the page at most 64 KiB and 20 s to compile),
//! and a bad request is a 4xx with a JSON error, never a panic of the server.

use std::net::IpAddr;

use anyhow::Context;
use clap::Args;

use crate::serve;

/// Arguments of `stirling serve`.
#[derive(Args, Debug)]
pub struct ServeArgs {
    /// Port to listen on (0: any free port; the address is printed on stderr)
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Address to bind (localhost by default; 0.0.0.0 exposes the page to the network)
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: IpAddr,
}

/// Listen and answer until the process is stopped.
pub fn run(a: &ServeArgs) -> anyhow::Result<()> {
    let server = tiny_http::Server::http((a.bind, a.port))
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("listening on {}:{}", a.bind, a.port))?;
    let addr = server
        .server_addr()
        .to_ip()
        .context("the server is not on an IP address")?;
    crate::common::note(format_args!(
        "serving the page on http://{addr}/ (Ctrl-C stops)"
    ));
    for request in server.incoming_requests() {
        serve::answer(request);
    }
    Ok(())
}
