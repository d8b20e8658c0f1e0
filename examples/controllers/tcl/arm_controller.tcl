#!/usr/bin/env tclsh
# A Caliper controller in Tcl, through Tcl Combat: finds the Model in the naming service, loads the
# shipped arm, drives one actuator, steps the simulation and prints the actuator's parameters
# before and after, with their units.
#
# Combat learns the signatures of the Model's operations from the type information the build
# generates from our IDL (build/idl/caliper/caliper_ir.tcl, see idl/backends/tclir.py); omniORB
# has no Interface Repository to ask.
#
# Exit status: 0 done, 1 the model cannot be reached or refused a request, 2 bad usage.

package require Tcl 8.6
package require combat

set script_dir [file dirname [file normalize [info script]]]
set source_dir [file normalize [file join $script_dir .. .. ..]]

proc usage {{channel stdout}} {
    global argv0
    puts $channel "usage: [file tail $argv0] \[options\]

Drives the arm through the Model component (caliper-model) over CORBA.

Options:
  --nameservice ADDR  corbaname::HOST:PORT of the naming service, or the model itself as
                      corbaname::HOST:PORT#HOST.host_cxt/model0.rtc
                      (default \$CALIPER_NAMESERVICE, else corbaname::127.0.0.1:2809)
  --ir FILE           Combat type information generated from the IDL
                      (default \$CALIPER_IR, else build/idl/caliper/caliper_ir.tcl)
  --model FILE        COLLADA scene to load (default models/ecce_arm.dae)
  --instance NAME     model instance in the naming service (default model0)
  --actuator NAME     actuator to drive (default elbow_flexor)
  --command VALUE     its command, in the actuator's unit (default 6, volts for a motor)
  --steps N           simulation steps to run (default 200)
  --pattern GLOB      parameters to read, repeatable (default *.ACTUATOR.*)
  --bench             also time 1,000 status calls and print the cost of one
  --bench-calls N     calls to time with --bench (default 1000)
  -h, --help          this text"
}

proc fail {message {code 1}} {
    puts stderr "arm_controller: $message"
    exit $code
}

# A CORBA exception as Combat raises it ({REPOID {member value ...}}) in readable form.
proc describe_error {err} {
    if {[catch {lindex $err 0} repoid] || ![string match IDL:* $repoid]} {
        return $err
    }
    set name [string map {/ ::} [regsub {^IDL:(omg\.org/)?(.*):[0-9.]+$} $repoid {\2}]]
    set members [lindex $err 1]
    if {[catch {dict size $members}] || [dict size $members] == 0} {
        return $name
    }
    if {[dict exists $members reason]} {
        return "$name: [dict get $members reason]"
    }
    set parts {}
    dict for {k v} $members { lappend parts "$k=$v" }
    return "$name ([join $parts {, }])"
}

# --- arguments ------------------------------------------------------------------------------

array set opt [list \
    nameservice [expr {[info exists env(CALIPER_NAMESERVICE)] && $env(CALIPER_NAMESERVICE) ne ""
                       ? $env(CALIPER_NAMESERVICE) : "corbaname::127.0.0.1:2809"}] \
    ir [expr {[info exists env(CALIPER_IR)] && $env(CALIPER_IR) ne ""
              ? $env(CALIPER_IR) : [file join $source_dir build idl caliper caliper_ir.tcl]}] \
    model [file join $source_dir models ecce_arm.dae] \
    instance model0 \
    actuator elbow_flexor \
    command 6 \
    steps 200 \
    pattern {} \
    bench 0 \
    bench-calls 1000]

set args $argv
while {[llength $args] > 0} {
    set args [lassign $args arg]
    switch -- $arg {
        -h - --help { usage; exit 0 }
        --bench { set opt(bench) 1 }
        --pattern {
            if {[llength $args] == 0} { fail "$arg needs a value" 2 }
            set args [lassign $args glob]
            lappend opt(pattern) $glob
        }
        --nameservice - --ir - --model - --instance - --actuator - --command - --steps -
        --bench-calls {
            if {[llength $args] == 0} { fail "$arg needs a value" 2 }
            set args [lassign $args opt([string range $arg 2 end])]
        }
        default { usage stderr; fail "unknown argument '$arg'" 2 }
    }
}
foreach key {steps bench-calls} {
    if {![string is integer -strict $opt($key)] || $opt($key) < 1} {
        fail "--$key needs a positive integer, not '$opt($key)'" 2
    }
}
if {![string is double -strict $opt(command)]} {
    fail "--command needs a number, not '$opt(command)'" 2
}
if {[llength $opt(pattern)] == 0} { set opt(pattern) [list "*.$opt(actuator).*"] }
if {![string match corbaname::* $opt(nameservice)]} {
    fail "the naming service address must look like corbaname::HOST:PORT, not '$opt(nameservice)'" 2
}
if {![file readable $opt(ir)]} {
    fail "no type information at $opt(ir) (build the caliper_ir target, or pass --ir FILE)"
}
if {[catch {uplevel #0 [list source $opt(ir)]} err]} {
    fail "cannot load the type information $opt(ir): $err"
}

# --- finding the model ----------------------------------------------------------------------

# CosNaming types for the two naming calls made through the DII (the generated file holds only
# Caliper's IDL).
set cos_name_component {struct IDL:omg.org/CosNaming/NameComponent:1.0 {id string kind string}}
set cos_not_found [list exception IDL:omg.org/CosNaming/NamingContext/NotFound:1.0 \
    [list why {enum {missing_node not_context not_object}} \
          rest_of_name [list sequence $cos_name_component]]]
set cos_binding [list struct IDL:omg.org/CosNaming/Binding:1.0 \
    [list binding_name [list sequence $cos_name_component] \
          binding_type {enum {nobject ncontext}}]]

# Host contexts bound in the root context, the local host's first.
proc host_contexts {root} {
    global cos_binding
    set spec [list void list \
        [list {in {unsigned long}} [list out [list sequence $cos_binding]] \
              {out {Object IDL:omg.org/CosNaming/BindingIterator:1.0}}] {}]
    corba::dii $root $spec 10000 bindings iterator
    if {$iterator ne "0" && $iterator ne ""} { catch {corba::release $iterator} }
    set local [lindex [split [info hostname] .] 0]
    set hosts {}
    foreach b $bindings {
        set name [dict get $b binding_name]
        if {[llength $name] != 1 || [dict get $b binding_type] ne "ncontext"} continue
        if {[dict get [lindex $name 0] kind] ne "host_cxt"} continue
        lappend hosts [dict get [lindex $name 0] id]
    }
    set hosts [lsort -unique $hosts]
    if {$local in $hosts} {
        set hosts [linsert [lsearch -all -inline -not -exact $hosts $local] 0 $local]
    }
    return $hosts
}

proc resolve_path {root path} {
    global cos_not_found
    return [corba::dii $root [list Object resolve_str {{in string}} [list $cos_not_found]] $path]
}

# The Model's reference and the naming path it was found under; its status answers.
proc find_model {address instance} {
    # corbaname::HOST:PORT[/KEY][#PATH]
    set rest [string range $address [string length corbaname::] end]
    set path ""
    if {[set hash [string first # $rest]] >= 0} {
        set path [corba::url_decode [string range $rest [expr {$hash + 1}] end]]
        set rest [string range $rest 0 [expr {$hash - 1}]]
    }
    if {[string first / $rest] < 0} { append rest /NameService }
    if {[catch {
        set root [corba::string_to_object "corbaloc::$rest"]
        set hosts [expr {$path eq "" ? [host_contexts $root] : {}}]
    } err]} {
        error "cannot reach the naming service at $address: [describe_error $err]"
    }
    if {$path ne ""} {
        set paths [list $path]
    } else {
        if {[llength $hosts] == 0} {
            corba::release $root
            error "no host contexts in the naming service at $address (is caliper-model running?)"
        }
        set paths [lmap host $hosts {string cat $host .host_cxt/ $instance .rtc}]
    }
    set tried {}
    foreach path $paths {
        if {[catch {resolve_path $root $path} model]} {
            lappend tried "$path: [describe_error $model]"
            continue
        }
        if {[catch {$model status} err]} {
            lappend tried "$path: does not answer ([describe_error $err])"
            catch {corba::release $model}
            continue
        }
        corba::release $root
        return [list $model $path]
    }
    corba::release $root
    error "no live model at $address\n  [join $tried "\n  "]"
}

if {[catch {find_model $opt(nameservice) $opt(instance)} found]} {
    fail $found
}
lassign $found model path
puts "model: $path via $opt(nameservice)"

# Any later failure of a call to the model: its reason, exit 1.
proc call {what args} {
    global model
    if {[catch {$model {*}$args} result]} {
        fail "$what failed: [describe_error $result]"
    }
    return $result
}

proc format_value {value} {
    set data [dict get $value data]
    set formatted {}
    foreach x $data { lappend formatted [format %.6g $x] }
    if {[llength $formatted] == 1} { return [lindex $formatted 0] }
    return "\[[join $formatted { }]\]"
}

# --- loading, driving, stepping -------------------------------------------------------------

set scene [file normalize $opt(model)]
call "load_scene $scene" load_scene $scene
set status [call status status]
puts [format "loaded: %s (state %s, time step %g s)" $scene [dict get $status state] \
    [dict get $status time_step]]
if {[dict get $status state] eq "RUNNING"} {
    puts "the simulation is running; pausing it to step it from here"
    call pause pause
}

set actuators [call actuators actuators]
puts "actuators ([llength $actuators]):"
set unit ""
foreach a $actuators {
    dict with a {
        puts [format "  %-20s %-16s tendon %-20s command \[%s\]" $name $kind $tendon \
            [expr {$command_unit eq "" ? "-" : $command_unit}]]
        if {$name eq $opt(actuator)} { set unit $command_unit }
    }
}
if {[lsearch -exact [lmap a $actuators {dict get $a name}] $opt(actuator)] < 0} {
    fail "no actuator '$opt(actuator)' in $scene"
}

set channels {}
foreach glob $opt(pattern) {
    set matching [call "list $glob" list $glob]
    if {[llength $matching] == 0} {
        fail "no parameters match '$glob'"
    }
    lappend channels {*}$matching
}
set ids [lmap c $channels {dict get $c id}]
set before [call get get $ids]

puts [format "set_command %s %g %s" $opt(actuator) $opt(command) $unit]
call set_command set_command $opt(actuator) $opt(command)
call "step $opt(steps)" step $opt(steps)
set status [call status status]
puts [format "stepped %d: sim_time %.6g s, %s steps, state %s" $opt(steps) \
    [dict get $status sim_time] [dict get $status steps] [dict get $status state]]
set after [call get get $ids]

puts "parameters matching [join $opt(pattern) {, }] ([llength $ids]):"
puts [format "  %-44s %14s %14s  %-10s %s" id before after unit kind]
set changed 0
foreach c $channels b $before a $after {
    set b [format_value $b]
    set a [format_value $a]
    set mark [expr {$b ne $a ? "*" : ""}]
    if {$mark ne ""} { incr changed }
    set kind [expr {[dict get $c is_static] ? "static" : "state"}]
    puts [format "  %-44s %14s %14s  %-10s %s%s" [dict get $c id] $b $a \
        [expr {[dict get $c unit] eq "" ? "-" : [dict get $c unit]}] $kind \
        [expr {$mark eq "" ? "" : "  changed"}]]
}
puts "$changed of [llength $ids] parameters changed"

# leave the actuator idle
call "set_command $opt(actuator) 0" set_command $opt(actuator) 0

# --- the cost of one call from Tcl ----------------------------------------------------------

if {$opt(bench)} {
    set n $opt(bench-calls)
    call status status  ;# warm
    set t0 [clock microseconds]
    for {set i 0} {$i < $n} {incr i} { $model status }
    set status_us [expr {double([clock microseconds] - $t0) / $n}]
    set one [list [lindex $ids 0]]
    set t0 [clock microseconds]
    for {set i 0} {$i < $n} {incr i} { $model get $one }
    set get_us [expr {double([clock microseconds] - $t0) / $n}]
    puts [format "BENCH status: %d calls, %.1f us per call" $n $status_us]
    puts [format "BENCH get(1 id): %d calls, %.1f us per call" $n $get_us]
}

corba::release $model
exit 0
