# A private certificate authority and certificates for TLS between components
# (`launch/caliper certs`), made with the openssl command line. Sourced by launch/caliper.
# Uses say and die when the sourcing script has them.
command -v say >/dev/null || say() { printf '%s\n' "$*" >&2; }
command -v die >/dev/null || die() { printf 'error: %s\n' "$*" >&2; exit 1; }

certs_usage() {
  cat <<'USAGE'
Usage: launch/caliper certs ca|host NAME|user NAME [--dir DIR] [--days N]

Makes a private certificate authority (CA) and certificates signed by it, for TLS between
Caliper components on a network (session --listen, node, components with --listen): every
process of a cluster shows a certificate of the cluster's CA and accepts only peers that do.

  ca          a new CA: DIR/ca.pem (its certificate; every host needs a copy) and
              DIR/private/ca.key with its password in DIR/private/ca.pass (keep these on the
              machine that signs; refuses to replace an existing CA)
  host NAME   a host's identity, used by the components and the naming service it runs:
              DIR/hosts/NAME.pem; NAME is the host name components bind under ($CALIPER_HOST,
              default `hostname -s`)
  user NAME   a user's identity, used by caliper-ctl, caliper-calibrate and the GUI tools:
              DIR/users/NAME.pem (default identity of a client: users/$USER)

An identity NAME.pem holds the private key (encrypted, AES-256) followed by its certificate and
the CA's; NAME.pass beside it holds the key's password (random, made here). omniORB needs a
non-empty key password: Caliper reads NAME.pass itself, nothing to type. Keys, passwords and
DIR/private are readable by their owner only (modes 0600 and 0700).

  --dir DIR   the PKI directory (default $CALIPER_PKI, else ~/.config/caliper/pki)
  --days N    validity of a new certificate in days (default 825; the CA: 3650)

To add another host: make its identity here (certs host NAME), then copy DIR/ca.pem,
DIR/hosts/NAME.pem and DIR/hosts/NAME.pass to the same paths under its PKI directory, keeping
the modes (e.g. `scp -p`). Certificates carry no expiry check in omniORB 4.2 beyond OpenSSL's
own, and no host-name check: anyone with a certificate of the CA is trusted, so keep the CA
private and one per cluster.
USAGE
}

# a random password for a key, written to FILE (mode 0600)
certs_password() {  # FILE
  (umask 077 && openssl rand -hex 32 >"$1") || die "cannot write $1"
}

certs_ca() {  # DIR DAYS
  local dir=$1 days=$2
  [ -e "$dir/ca.pem" ] && die "a CA exists already in $dir (ca.pem): certificates it signed would no longer be accepted if it were replaced; remove $dir yourself to start anew"
  mkdir -p "$dir/private" && chmod 700 "$dir/private" || die "cannot create $dir/private"
  certs_password "$dir/private/ca.pass"
  (umask 077 && openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -aes-256-cbc \
    -pass "file:$dir/private/ca.pass" -out "$dir/private/ca.key" 2>"$dir/private/openssl.err") ||
    die "openssl genpkey failed: $(cat "$dir/private/openssl.err")"
  local id
  id=$(openssl rand -hex 4)
  openssl req -x509 -new -key "$dir/private/ca.key" -passin "file:$dir/private/ca.pass" \
    -sha256 -days "$days" -subj "/O=Caliper/CN=Caliper CA $id" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign" \
    -out "$dir/ca.pem" 2>"$dir/private/openssl.err" ||
    die "openssl req failed: $(cat "$dir/private/openssl.err")"
  chmod 644 "$dir/ca.pem"
  rm -f "$dir/private/openssl.err"
  say "CA 'Caliper CA $id': $dir/ca.pem (copy it to every host), key in $dir/private/"
}

certs_identity() {  # DIR KIND(hosts|users) NAME DAYS
  local dir=$1 kind=$2 name=$3 days=$4
  [[ "$name" =~ ^[A-Za-z0-9][A-Za-z0-9._-]*$ ]] ||
    die "certs: '$name' is not a valid name (letters, digits, '.', '_', '-')"
  [ -f "$dir/ca.pem" ] && [ -f "$dir/private/ca.key" ] ||
    die "no CA in $dir: make one first with launch/caliper certs ca${CERTS_DIR_ARG}"
  local out=$dir/$kind/$name tmp
  [ -e "$out.pem" ] && die "$out.pem exists already; remove it (and $out.pass) to make a new one"
  mkdir -p "$dir/$kind" && chmod 700 "$dir/$kind" || die "cannot create $dir/$kind"
  tmp=$(mktemp -d) || die "mktemp failed"
  certs_password "$out.pass"
  local ou=${kind%s}
  if ! (umask 077 &&
      openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -aes-256-cbc \
        -pass "file:$out.pass" -out "$tmp/key.pem" &&
      openssl req -new -key "$tmp/key.pem" -passin "file:$out.pass" \
        -subj "/O=Caliper/OU=$ou/CN=$name" -out "$tmp/req.pem" &&
      printf '%s\n' "basicConstraints=critical,CA:FALSE" \
        "keyUsage=critical,digitalSignature,keyAgreement" \
        "extendedKeyUsage=serverAuth,clientAuth" "subjectAltName=DNS:$name" >"$tmp/ext.cnf" &&
      openssl x509 -req -in "$tmp/req.pem" -CA "$dir/ca.pem" -CAkey "$dir/private/ca.key" \
        -passin "file:$dir/private/ca.pass" -CAcreateserial -CAserial "$dir/private/ca.srl" \
        -sha256 -days "$days" -extfile "$tmp/ext.cnf" -out "$tmp/cert.pem" &&
      cat "$tmp/key.pem" "$tmp/cert.pem" "$dir/ca.pem" >"$out.pem") 2>"$tmp/openssl.err"; then
    local why
    why=$(cat "$tmp/openssl.err")
    rm -rf "$tmp"
    rm -f "$out.pem" "$out.pass"
    die "openssl failed making $out.pem: $why"
  fi
  rm -rf "$tmp"
  chmod 600 "$out.pem" "$out.pass"
  openssl verify -CAfile "$dir/ca.pem" "$out.pem" >/dev/null 2>&1 ||
    die "the new certificate $out.pem does not verify against $dir/ca.pem"
  say "$ou '$name': $out.pem (key, certificate and CA), key password in $out.pass"
}

cmd_certs() {
  local kind="" name="" dir=${CALIPER_PKI:-$HOME/.config/caliper/pki} days=""
  CERTS_DIR_ARG=""
  while [ $# -gt 0 ]; do
    case "$1" in
      --dir) [ $# -ge 2 ] || die "certs: --dir needs a directory"; dir=$2
        CERTS_DIR_ARG=" --dir $2"; shift 2 ;;
      --days) [ $# -ge 2 ] || die "certs: --days needs a number"; days=$2; shift 2 ;;
      -h|--help) certs_usage; return 0 ;;
      -*) die "certs: unknown option $1 (see launch/caliper certs --help)" ;;
      *)
        if [ -z "$kind" ]; then kind=$1
        elif [ -z "$name" ]; then name=$1
        else die "certs: unexpected argument $1 (see launch/caliper certs --help)"; fi
        shift ;;
    esac
  done
  command -v openssl >/dev/null || die "certs: the openssl command is missing (apt-get install openssl)"
  [ -z "$days" ] || [[ "$days" =~ ^[1-9][0-9]{0,4}$ ]] || die "certs: --days takes a whole number of days"
  case "$kind" in
    ca)
      [ -z "$name" ] || die "certs ca takes no name"
      mkdir -p "$dir" || die "cannot create $dir"
      certs_ca "$dir" "${days:-3650}" ;;
    host|user)
      [ -n "$name" ] || die "certs $kind NAME: the name is missing"
      certs_identity "$dir" "${kind}s" "$name" "${days:-825}" ;;
    "") certs_usage >&2; die "certs: say what to make: ca, host NAME or user NAME" ;;
    *) die "certs: '$kind' is not ca, host or user (see launch/caliper certs --help)" ;;
  esac
}
