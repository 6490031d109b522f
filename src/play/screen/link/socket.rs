//! The one part of the link a program inside a multiplexer over SSH can see: the bytes sshd's
//! socket holds for the connection, in the kernel's table of TCP sockets.

use std::net::IpAddr;

/// Finds the bytes waiting in the send queue of the SSH connection `ssh_connection` (the
/// `SSH_CONNECTION` variable: client address and port, server address and port) in `table`,
/// the text of `/proc/net/tcp` and `/proc/net/tcp6` (Linux; their `tx_queue` column: bytes
/// written and not yet acknowledged by the client). Inside a multiplexer over SSH this is the
/// one part of the link the program can see: the queue its frames build in sshd's socket.
/// `None` when the connection is not in the table (another network namespace, a multiplexer
/// attached from elsewhere since the player started, not Linux).
pub fn ssh_send_queue(table: &str, ssh_connection: &str) -> Option<u64> {
    let mut fields = ssh_connection.split_whitespace();
    let (client, client_port, server, server_port) = (fields.next()?, fields.next()?, fields.next()?, fields.next()?);
    let (client, server): (IpAddr, IpAddr) = (client.parse().ok()?, server.parse().ok()?);
    let (client_port, server_port): (u16, u16) = (client_port.parse().ok()?, server_port.parse().ok()?);
    let local = (kernel_hex(server), server_port);
    let remote = (kernel_hex(client), client_port);
    table.lines().find_map(|line| {
        let mut columns = line.split_whitespace();
        let _slot = columns.next()?;
        let (l, r) = (parse_endpoint(columns.next()?)?, parse_endpoint(columns.next()?)?);
        let _state = columns.next()?;
        let tx_queue = columns.next()?.split(':').next()?;
        (local.0.contains(&l.0) && l.1 == local.1 && remote.0.contains(&r.0) && r.1 == remote.1)
            .then(|| u64::from_str_radix(tx_queue, 16).ok())
            .flatten()
    })
}

/// An endpoint of `/proc/net/tcp*`: the address as the kernel prints it (hex words in this
/// machine's byte order) and the port.
fn parse_endpoint(text: &str) -> Option<(String, u16)> {
    let (address, port) = text.split_once(':')?;
    Some((address.to_ascii_uppercase(), u16::from_str_radix(port, 16).ok()?))
}

/// The ways the kernel prints `address` in `/proc/net/tcp*`: 32-bit words of the address in
/// this machine's byte order, `%08X` each; an IPv4 address also as IPv4-mapped IPv6 (a server
/// listening on `::` takes IPv4 clients so).
fn kernel_hex(address: IpAddr) -> Vec<String> {
    let words = |octets: &[u8]| -> String {
        octets.chunks(4).map(|w| format!("{:08X}", u32::from_ne_bytes([w[0], w[1], w[2], w[3]]))).collect()
    };
    match address {
        IpAddr::V4(v4) => vec![words(&v4.octets()), words(&v4.to_ipv6_mapped().octets())],
        IpAddr::V6(v6) => {
            let mut forms = vec![words(&v6.octets())];
            if let Some(v4) = v6.to_ipv4_mapped() {
                forms.push(words(&v4.octets()));
            }
            forms
        }
    }
}
