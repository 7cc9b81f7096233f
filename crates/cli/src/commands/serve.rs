//! `specula serve`: the BRDF explorer (`crates/serve`), served by the binary itself.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};

use super::CommandResult;

/// Arguments of `specula serve`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The port to listen on (0 picks a free one).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// The address to listen on; anything but loopback exposes the explorer to the network.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    bind: IpAddr,
    /// Open the explorer in the default browser.
    #[arg(long)]
    open: bool,
}

/// Serves until Ctrl-C.
pub fn run(args: &Args) -> CommandResult {
    specula_serve::serve(SocketAddr::new(args.bind, args.port), args.open)
}
